#!/usr/bin/env bash
# Run the Blender tests against older Blender releases (the extension promises 4.2 LTS .. 5.0).
#
#   bash tools/check_blender_versions.sh 4.2.23 [4.3.0 4.4.0 4.5.15 ...]
#
# For each bpy VERSION it makes (or reuses) a venv at ${VENV_ROOT:-/tmp}/venv-bpy<VERSION> with
# torch 2.13.0 (CPU, from local disk, installed first and alone), bpy==VERSION, numpy<2, the
# project's dependencies, pillow (the render checks read PNGs) and an editable install of this
# tree, then runs tests/test_blender_*.py with that venv's python (the tests start their Blender
# subprocess with the same interpreter, so they use that bpy). TESTS="..." picks other test files.
# Not part of CI: each bpy wheel is ~300 MB. The project's own .venv is not touched.
# Exit status: non-zero if any version failed; a summary line per version at the end.
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
[ $# -ge 1 ] || { echo "usage: $0 BPY_VERSION [BPY_VERSION ...]   e.g. 4.2.23 4.4.0" >&2; exit 2; }
PYTHON=${PYTHON:-python3}
TESTS=${TESTS:-$(echo tests/test_blender_*.py)}
status=0
summary=()
pip_install() {  # quiet, without the local indexes' "Location ... is ignored" noise
  "$venv/bin/python" -m pip install -q "$@" 2> >(grep -v "is ignored: it is neither" >&2)
}
for version in "$@"; do
  venv=${VENV_ROOT:-/tmp}/venv-bpy$version
  start=$SECONDS
  if [ ! -f "$venv/.installed" ]; then
    echo "== creating $venv"
    rm -rf "$venv"
    "$PYTHON" -m venv "$venv" &&
    pip_install torch==2.13.0 &&
    pip_install "bpy==$version" "numpy>=1.24,<2" "scipy>=1.10" "transformers>=4.44" "sentencepiece>=0.2" \
      "smplx>=0.1.28" "safetensors>=0.4" "tqdm>=4.66" "pytest>=8" pillow &&
    pip_install --no-deps -e "$ROOT" &&
    touch "$venv/.installed" || { summary+=("bpy $version: venv install FAILED"); status=1; continue; }
    echo "== installed in $((SECONDS - start)) s"
  fi
  got=$("$venv/bin/python" -c "import bpy; print(bpy.app.version_string)" 2>/dev/null)
  echo "== bpy $version (Blender $got): pytest $TESTS"
  log=$venv/pytest.log
  "$venv/bin/python" -m pytest -q -p no:cacheprovider $TESTS 2>&1 | tee "$log"
  rc=${PIPESTATUS[0]}
  [ "$rc" -eq 0 ] || status=1
  summary+=("bpy $version (Blender $got): $(grep -E '(passed|failed|error)' "$log" | tail -1) [$((SECONDS - start)) s]")
done
echo "== summary"
printf '%s\n' "${summary[@]}"
exit $status
