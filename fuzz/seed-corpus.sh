#!/usr/bin/env bash
# Fills fuzz/corpus/<target>/ with the seed inputs of every fuzz target: the golden
# traces of traces/ in each encoding, the DO_FILL fixtures and embedded scenes, and the
# OBJ seeds of fuzz/seeds/obj/. Run from anywhere; it builds cwisim to convert the traces.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
corpus="$root/fuzz/corpus"
mkdir -p "$corpus"/{trace_cwt,trace_jsonl,trace_cwb,screen_scene,world_scene,obj}
cargo build --release --locked --manifest-path "$root/Cargo.toml" -q
cwisim="$root/target/release/cwisim"
for t in "$root"/traces/*.cwt; do
  name=$(basename "$t" .cwt)
  cp "$t" "$corpus/trace_cwt/$name.cwt"
  "$cwisim" convert "$t" -o "$corpus/trace_jsonl/$name.jsonl"
  "$cwisim" convert "$t" -o "$corpus/trace_cwb/$name.cwb"
done
cp "$root"/crates/ypipe/tests/fixtures/*.json "$corpus/screen_scene/"
cp "$root"/crates/world/scenes/{fig25,cases12}.json "$corpus/screen_scene/"
cp "$root"/crates/world/scenes/*.json "$corpus/world_scene/"
cp "$root"/fuzz/seeds/obj/*.obj "$corpus/obj/"
echo "seeded $(find "$corpus" -type f | wc -l) inputs under $corpus"
