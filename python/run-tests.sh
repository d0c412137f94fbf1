#!/usr/bin/env bash
# Builds the Python package into a virtual environment and runs its pytest tests.
#
# The venv is $SMC_LMB_VENV (default: .venv at the repository root); maturin, pytest, numpy and ray
# come from the package registry. The extension is built in the dev profile (opt-level 2,
# python/Cargo.toml) into the root workspace's target directory, where `cargo test
# --workspace` has already compiled most of its dependencies with the same settings.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
venv="${SMC_LMB_VENV:-$repo/.venv}"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$repo/target}"
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check maturin pytest numpy ray
export VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH"
(cd "$repo/python" && maturin develop --quiet)
python -m pytest -q "$repo/python/tests"
