#!/usr/bin/env bash
# Regenerates fuzz/corpus/tcbc/seed-*.tcbc after a .tcbc format change:
# short pieces of the bundled CMU capture compressed by `tcb compress`
# (at the default tolerance; one with 32-key blocks; one of the whole clip
# at every 8th frame, whose root rotation is stored relative to a center;
# one of that clip reduced, with tracks on key times of their own),
# then one of them truncated and one with a byte changed.
#
#   bash fuzz/make-tcbc-seeds.sh        # from the repository's root
set -euo pipefail
out=fuzz/corpus/tcbc
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cargo build --release -q -p tcb-cli
tcb=target/release/tcb
bvh=data/cmu-01_01.bvh
# The BVH with the first $1 frames, every $2-th, frame time times $2.
cut() {
  awk -v keep="$1" -v every="$2" '
    /^Frames:/ { print "Frames: " keep; next }
    /^Frame Time:/ { printf "Frame Time: %.7f\n", $3 * every; motion = 1; next }
    motion { if ((n++ % every) == 0 && kept < keep) { print; kept++ } next }
    { print }' "$bvh"
}
cut 40 1 > "$work/tiny.bvh"
cut 344 8 > "$work/every8.bvh"
$tcb compress "$work/tiny.bvh" -o "$out/seed-tiny.tcbc" > /dev/null
$tcb compress "$work/tiny.bvh" -o "$out/seed-blocks.tcbc" --seek-keys 32 > /dev/null
$tcb compress "$work/every8.bvh" -o "$out/seed-centered.tcbc" --tolerance 0.05 > /dev/null
# A reduced clip: tracks on key times of their own beside the grid's.
$tcb reduce "$work/every8.bvh" --rotation hermite -o "$work/reduced.json" --tolerance 0.05 > /dev/null 2>&1
$tcb compress "$work/reduced.json" -o "$out/seed-own-key-times.tcbc" --tolerance 0.05 > /dev/null 2>&1
size=$(stat -c %s "$out/seed-tiny.tcbc")
head -c $((size / 2)) "$out/seed-tiny.tcbc" > "$out/seed-tiny-truncated.tcbc"
# One byte of the stream changed (the checksum then disagrees).
python3 - "$out/seed-tiny.tcbc" "$out/seed-tiny-corrupted.tcbc" <<'PY'
import sys
b = bytearray(open(sys.argv[1], 'rb').read())
b[len(b) // 2] ^= 0x5a
open(sys.argv[2], 'wb').write(b)
PY
rm -f "$out/seed-tiny-with-times.tcbc"
ls -l "$out"/seed-*.tcbc
