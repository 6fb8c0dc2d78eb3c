//! The `cwisim` binary; everything is in the `cwisim_host` library.

fn main() -> std::process::ExitCode {
    cwisim_host::cli::main()
}
