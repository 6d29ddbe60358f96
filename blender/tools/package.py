"""Packs the Blender add-on and extension (run by scripts/build-blender-addon.sh; stdlib only).

    python3 package.py --out OUT --version V (--wheel W.whl | --native LIB.so)

--native makes the wheel from an extension module already built (a `cargo build -p inbetween-py`
library, as the tests use) and the Python sources of crates/py, instead of a maturin wheel.
Writes OUT/inbetween_blender/ (the add-on for Blender 3.4+: the sources plus the package unpacked
in _vendor/) and OUT/inbetween_blender-V.zip (the extension for 4.2+: the sources, a manifest
naming the wheel and its platform, and the wheel in wheels/)."""

from __future__ import annotations

import argparse
import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT / "blender" / "inbetween_blender"
PACKAGE = ROOT / "crates" / "py" / "python" / "inbetween"
SKIP = {"__pycache__", "_vendor"}
#: Blender's platform names for the wheel tags we build.
PLATFORMS = {"linux_x86_64": "linux-x64", "linux_aarch64": "linux-arm64", "macosx": "macos", "win_amd64": "windows-x64"}


def fail(msg: str) -> None:
    print(f"build-blender-addon: {msg}", file=sys.stderr)
    sys.exit(1)


def _record_line(name: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def make_wheel(native: Path, version: str, out_dir: Path) -> Path:
    """A wheel (PEP 427) of the package with `native` as inbetween/_native.abi3.so."""
    plat = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    tag = f"cp310-abi3-{plat}"
    name = f"inbetween-{version}-{tag}.whl"
    files = {}
    for p in sorted(PACKAGE.iterdir()):
        if p.is_file() and p.suffix in (".py", ".pyi", ".typed"):
            files[f"inbetween/{p.name}"] = p.read_bytes()
    with tempfile.TemporaryDirectory() as tmp:
        so = Path(tmp) / "_native.abi3.so"
        shutil.copyfile(native, so)
        if shutil.which("strip"):
            # Debug info is most of a dev build (86 MB -> 26 MB); the code is the same.
            subprocess.run(["strip", "--strip-debug", str(so)], check=True)
        files["inbetween/_native.abi3.so"] = so.read_bytes()
    info = f"inbetween-{version}.dist-info"
    files[f"{info}/METADATA"] = (
        f"Metadata-Version: 2.1\nName: inbetween\nVersion: {version}\nRequires-Python: >=3.10\n"
        "Requires-Dist: numpy>=1.24\n"
    ).encode()
    files[f"{info}/WHEEL"] = (
        f"Wheel-Version: 1.0\nGenerator: inbetween build-blender-addon\nRoot-Is-Purelib: false\nTag: {tag}\n"
    ).encode()
    record = [_record_line(n, d) for n, d in files.items()] + [f"{info}/RECORD,,"]
    files[f"{info}/RECORD"] = ("\n".join(record) + "\n").encode()
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / name
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for n, d in files.items():
            z.writestr(n, d)
    return path


def source_files():
    for p in sorted(SOURCE.rglob("*")):
        rel = p.relative_to(SOURCE)
        if p.is_file() and not (set(rel.parts) & SKIP) and p.suffix != ".pyc":
            yield p, rel


def check_version(version: str) -> None:
    text = (SOURCE / "__init__.py").read_text()
    m = re.search(r'"version":\s*\((\d+),\s*(\d+),\s*(\d+)\)', text)
    if not m or ".".join(m.groups()) != version:
        fail(f"bl_info version {m.groups() if m else None} in {SOURCE / '__init__.py'}: expected {version} (Cargo.toml)")


def manifest(version: str, wheel: Path) -> str:
    text = (SOURCE / "blender_manifest.toml").read_text()
    text = re.sub(r'(?m)^version = ".*"$', f'version = "{version}"', text)
    plat = next((b for w, b in PLATFORMS.items() if w in wheel.name), None)
    if plat is None:
        fail(f"{wheel.name}: no Blender platform known for this wheel's tag")
    return text + f'\nplatforms = ["{plat}"]\nwheels = ["./wheels/{wheel.name}"]\n'


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--version", required=True)
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--wheel", type=Path)
    src.add_argument("--native", type=Path)
    args = ap.parse_args()
    check_version(args.version)
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        if args.native:
            if not args.native.is_file():
                fail(f"{args.native}: no such extension module (cargo build -p inbetween-py --lib)")
            wheel = make_wheel(args.native, args.version, Path(tmp))
        else:
            wheel = args.wheel
            if not wheel.is_file():
                fail(f"{wheel}: no such wheel")
        # The 3.x add-on folder, built beside and renamed into place (never half-written).
        addon = out / "inbetween_blender"
        staging = Path(tempfile.mkdtemp(dir=out, prefix=".inbetween_blender."))
        staging.chmod(0o755)
        for p, rel in source_files():
            (staging / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(p, staging / rel)
        with zipfile.ZipFile(wheel) as z:
            z.extractall(staging / "_vendor")
        so = staging / "_vendor" / "inbetween" / "_native.abi3.so"
        if so.exists():
            so.chmod(0o755)
        if addon.exists():
            shutil.rmtree(addon)
        staging.rename(addon)
        # The 4.2+ extension zip.
        zpath = out / f"inbetween_blender-{args.version}.zip"
        part = zpath.with_suffix(".zip.part")
        with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
            for p, rel in source_files():
                if rel.name != "blender_manifest.toml":
                    z.write(p, rel.as_posix())
            z.writestr("blender_manifest.toml", manifest(args.version, wheel))
            z.write(wheel, f"wheels/{wheel.name}")
        os.replace(part, zpath)
        shutil.copyfile(wheel, out / wheel.name)
    print(f"{addon}\n{zpath}\n{out / wheel.name}")


if __name__ == "__main__":
    main()
