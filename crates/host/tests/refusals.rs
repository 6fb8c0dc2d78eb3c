//! Flags that would do nothing are refused, and edge values are said plainly (issue 53,
//! item 10): `--watch` without what reads it, `--repeat 0`, a sweep of no setting, a frame
//! past the last u64; and a trace written to a device without an extension is text, as
//! LIMITS.md says.

mod common;

use common::{cwisim, scratch, text};

/// `cwisim ARGS`: exit 2, one line on standard error containing `says`.
fn refused(args: &[&str], says: &str) {
    let dir = scratch(&format!("refusals-{}", args[0]));
    let out = cwisim(&dir, args);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "cwisim {args:?}: {stderr}");
    assert!(stderr.contains(says), "cwisim {args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}

#[test]
fn flags_that_would_do_nothing_are_refused() {
    refused(
        &[
            "rtl",
            "--numeric",
            "fixed:I=2.15,dI=1.16,ddI=1.16",
            "-o",
            "x.v",
            "--watch",
            "0,1",
        ],
        "--watch chooses the processors",
    );
    refused(
        &[
            "tradeoff",
            "fig25",
            "--repeat",
            "0",
            "--renderers",
            "vanrij",
        ],
        "repeat must be at least 1",
    );
    refused(
        &["tradeoff", "pot", "--renderers", "nishita"],
        "no setting to measure: every renderer asked for is left out (nishita: ",
    );
    refused(
        &[
            "inspect",
            "fig25",
            "--frames",
            "18446744073709551615",
            "-o",
            "p.html",
        ],
        "--frames: frame 18446744073709551615 is beyond any trace",
    );
}

#[test]
fn a_trace_to_a_device_without_an_extension_is_text() {
    let dir = scratch("refusals-stdout-trace");
    let out = cwisim(&dir, &["emit", "fig25", "-o", "/dev/stdout"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stdout.starts_with("cwisim-trace version=1"), "{stdout}");
    // a regular file still needs its extension
    let out = cwisim(&dir, &["emit", "fig25", "-o", "trace"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("unknown trace extension"), "{stderr}");
}
