#!/usr/bin/env bash
# Builds the Blender add-on and extension from blender/inbetween_blender and the inbetween Python package:
#
#   scripts/build-blender-addon.sh OUT [--native LIB]
#
# OUT/inbetween_blender/            the add-on for Blender 3.4+ (copy it into Blender's scripts/addons/);
#                                   the package is unpacked in its _vendor/ folder
# OUT/inbetween_blender-<v>.zip     the extension for Blender 4.2+ (Edit > Preferences > Get Extensions >
#                                   Install from Disk), the package as a wheel inside
# OUT/inbetween-<v>-cp310-abi3-<platform>.whl   the wheel itself
#
# Without --native the wheel is a release build by maturin (`pip install maturin`; for older glibc
# add `pip install ziglang` and set MATURIN_ARGS="--zig --compatibility manylinux_2_28"). With --native LIB
# the wheel is made from an extension module already built (e.g. $CARGO_TARGET_DIR/debug/lib_native.so
# from `cargo build -p inbetween-py --lib`), debug info stripped: what the tests use.
set -euo pipefail
if [ $# -lt 1 ] || [ "${1:0:1}" = "-" ]; then
    sed -n '2,17p' "$0" >&2
    exit 2
fi
OUT="$1"
shift
NATIVE=""
while [ $# -gt 0 ]; do
    case "$1" in
        --native) NATIVE="${2:?--native takes the path of lib_native.so}"; shift 2 ;;
        *) echo "build-blender-addon: unknown argument $1" >&2; exit 2 ;;
    esac
done
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
VERSION="$(sed -n 's/^version = "\(.*\)"$/\1/p' "$ROOT/Cargo.toml" | head -n 1)"
PYTHON="${PYTHON:-python3}"
mkdir -p "$OUT"
if [ -n "$NATIVE" ]; then
    exec "$PYTHON" "$ROOT/blender/tools/package.py" --out "$OUT" --version "$VERSION" --native "$NATIVE"
fi
command -v maturin >/dev/null || { echo "build-blender-addon: maturin not found (pip install maturin), or pass --native LIB" >&2; exit 1; }
WHEELS="$(mktemp -d)"
trap 'rm -rf "$WHEELS"' EXIT
# shellcheck disable=SC2086
maturin build --release -m "$ROOT/crates/py/Cargo.toml" -o "$WHEELS" ${MATURIN_ARGS:-}
WHEEL="$(ls "$WHEELS"/inbetween-*.whl | head -n 1)"
"$PYTHON" "$ROOT/blender/tools/package.py" --out "$OUT" --version "$VERSION" --wheel "$WHEEL"
