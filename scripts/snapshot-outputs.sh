#!/usr/bin/env bash
# Runs a fixed set of CLI commands (the demo, every built-in script story, the mocap codec on real takes,
# camera, face and video on the demo's own inputs) with the binary BIN, writing into DIR, so a refactor can be
# checked byte for byte:  scripts/snapshot-outputs.sh BIN DIR && diff -r before/ DIR
# Files whose contents hold timings (stdout logs, reports) are removed at the end; everything else must match.
# Real-data steps run only when ../shared/data (or $INBETWEEN_DATA) exists.
set -euo pipefail
BIN="$(realpath "$1")"
OUT="$2"
DATA="${INBETWEEN_DATA:-$(cd "$(dirname "$0")/.." && pwd)/../shared/data}"
rm -rf "$OUT"
mkdir -p "$OUT"
cd "$OUT"
run() { "$BIN" "$@" > /dev/null 2>&1 || { echo "snapshot: failed: inbetween $*" >&2; exit 1; }; }

run demo -o demo
for s in $("$BIN" script stories 2>/dev/null | awk '/^[a-z0-9_-]+ /{print $1}'); do
    run script scene "builtin:$s" -o "scene-$s"
    run script run "builtin:$s" -o "story-$s" --gif-width 160
done
run script run builtin:demo -o story-demo-noopt --no-optimize --gif-width 160

if [ -d "$DATA/mocap/cmu" ]; then
    for t in cgspeed/131_01 cgspeed/01_01; do
        n=$(basename "$t")
        run mocap compress "$DATA/mocap/cmu/$t.bvh" --max-error 1cm -o "mocap-$n.ibk"
        run mocap decompress "mocap-$n.ibk" -o "mocap-$n.rec.bvh"
    done
    # Fixed key count (the exact optimum over windows): the short take only, the long one takes minutes.
    run mocap compress "$DATA/mocap/cmu/cgspeed/131_01.bvh" -k 10 -o mocap-131_01-k10.ibk
    run mocap decompress mocap-131_01-k10.ibk -o mocap-131_01-k10.rec.bvh
    run convert "$DATA/mocap/cmu/asf_amc/11_01.amc" --asf "$DATA/mocap/cmu/asf_amc/11.asf" -o conv-11_01.bvh --fps 30
    run preview "$DATA/mocap/cmu/cgspeed/131_01.bvh" -o preview-131_01.png --frame 40
    if [ -d "$DATA/assets/kenney_furniture" ]; then
        run script run builtin:demo -o story-demo-models --models "$DATA/assets/kenney_furniture" --gif-width 160
    fi
fi
# Logs and reports that print wall-clock times differ from run to run (the video metric's cache
# records its training seconds too).
find . \( -name '*.log' -o -name 'report.txt' -o -name 'report.md' -o -name 'costs.png' -o -path '*/video-cache/*' \) -delete
echo "snapshot: $(find . -type f | wc -l) files in $OUT"
