#!/usr/bin/env bash
# Every test of omniloop: the Rust workspace's (unit, end-to-end, the import-loop check), then
# the Python package's, in a virtual environment (.venv, made on first use) where
# `pip install ./python` builds the extension with the tests' own cargo profile, so that the
# workspace is compiled once for both.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo test --workspace
# The binary cargo test just built: python/tests/test_ssl.py serves its games with it.
export OMNILOOP_BIN="$PWD/target/debug/omniloop"

venv="${OMNILOOP_VENV:-.venv}"
if [ ! -x "$venv/bin/python" ]; then
  echo "omniloop: making the virtual environment $venv for the Python tests"
  python3 -m venv "$venv"
  "$venv/bin/python" -m pip install -q --upgrade pip
fi
# The dev profile is the one `cargo test` just built: the extension reuses its artifacts. The
# `ros` extra brings ROS 2 (rclpy, Fast DDS, the messages) for the ROS 2 bridge's tests.
MATURIN_PEP517_ARGS="--profile dev" "$venv/bin/python" -m pip install -q "./python[test,ros]"
# pySSLVision, a Small-Size team's vision client that python/tests/test_ssl.py runs against
# `omniloop ssl`, pins protobuf 3.20.3 (it fails on 4 and later): its own environment.
sslvision="${OMNILOOP_SSLVISION_VENV:-.venv-sslvision}"
if [ ! -x "$sslvision/bin/python" ] || ! "$sslvision/bin/python" -c "import pySSLVision.VisionComm" 2>/dev/null; then
  echo "omniloop: making the virtual environment $sslvision for pySSLVision"
  python3 -m venv "$sslvision"
  "$sslvision/bin/python" -m pip install -q pysslvision==2.0.0 protobuf==3.20.3
fi
# The Python tests in parallel (pytest-xdist, in the test extra): a worker a core, four at most;
# each test keeps its own ports, folders and ROS 2 domain.
"$venv/bin/python" -m pytest -q -n logical --maxprocesses 4 python/tests
# The package's types: mypy --strict on the package and its examples (the settings in
# python/pyproject.toml's [tool.mypy]), then stubtest, the native module's stub
# (omniloop/_omniloop.pyi) against the module built above.
"$venv/bin/python" -m mypy --config-file python/pyproject.toml python/omniloop python/examples
"$venv/bin/python" -m mypy.stubtest omniloop._omniloop --allowlist python/stubtest-allowlist.txt
