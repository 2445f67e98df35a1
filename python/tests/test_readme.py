"""The README and the docs cannot drift: the README's Python example is the example file and
runs, every command it shows runs, and every Python block of docs/ type-checks."""

import ast
import builtins
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT


def readme_python_block() -> str:
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_example_is_the_example_file():
    assert readme_python_block() == (ROOT / "python/examples/drive_to_goal.py").read_text()


def test_the_example_runs_and_reaches_the_goal():
    out = subprocess.run(
        [sys.executable, "python/examples/drive_to_goal.py"],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "reached goal: True contacts: 0"


# --- Every command the README shows runs here, as written but for what the test run itself
# already does (the script that runs these tests, the pip install it made).

def readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```sh\n(.*?)```", text, re.S)
    return [line for block in blocks for line in block.splitlines() if line.strip()]


def as_run_here(command: str) -> str | None:
    """The shell command that runs `command` in this test, or None where the test run has
    already done it (a README command this function does not know fails the test)."""
    if command == "scripts/test.sh":
        return None  # the script running these tests
    if command.startswith("pip install "):
        return None  # scripts/test.sh installed ./python with every extra the README names
    # `cargo run --` builds and runs target/debug/omniloop: scripts/test.sh's `cargo test`
    # built it with the same profile, and OMNILOOP_BIN names it.
    binary = os.environ.get("OMNILOOP_BIN") or str(ROOT / "target/debug/omniloop")
    command = command.replace("cargo run -- ", f"{binary} ")
    if "cargo " in command:
        raise AssertionError(f"the README runs cargo in a way this test does not know: {command}")
    return command


def test_the_readme_names_the_commands_ci_runs():
    commands = readme_commands()
    assert commands[:2] == ["scripts/install-deps.sh && cargo run -- replay corner55", "scripts/test.sh"]
    assert "pip install ./python" in commands and "python python/examples/drive_to_goal.py" in commands
    ci = (ROOT / ".ci/run").read_text()
    assert "scripts/install-deps.sh" in ci and "scripts/test.sh" in ci


@pytest.mark.long
@pytest.mark.parametrize("command", readme_commands())
def test_every_readme_command_runs(command):
    shell = as_run_here(command)
    if shell is None:
        return
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    # A command sent to the background with `&` must succeed too: wait for each by its pid.
    shell = shell.replace(" & ", ' & pids="$pids $!"; ')
    out = subprocess.run(
        ["bash", "-c", f"set -e; pids=; {shell}; for p in $pids; do wait $p; done"],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=600,
    )
    assert out.returncode == 0, f"{command}\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}"


# --- Every Python block of docs/ type-checks against the package (its stub included); names a
# fragment takes from the text around it (`scenario`, `my_robot`) are declared as Any.

def docs_python_blocks() -> list[tuple[str, str]]:
    blocks = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        for i, block in enumerate(re.findall(r"```python\n(.*?)```", page.read_text(), re.S)):
            blocks.append((f"{page.stem}_{i}", block))
    return blocks


#: Modules a fragment uses without importing them, as the page around it imports them.
IMPORTS = {"omniloop": "import omniloop", "np": "import numpy as np", "cv2": "import cv2"}


def free_names(source: str) -> set[str]:
    tree = ast.parse(source)
    bound = set(dir(builtins))
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
            bound.add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            bound.add(node.name)
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
    return used - bound


@pytest.mark.long
def test_every_python_block_in_the_docs_type_checks(tmp_path):
    blocks = docs_python_blocks()
    assert len(blocks) >= 10
    for name, block in blocks:
        free = free_names(block)
        modules = [IMPORTS[n] for n in sorted(free & IMPORTS.keys())]
        names = [f"{n}: Any" for n in sorted(free - IMPORTS.keys())]
        prelude = "\n".join(["from typing import Any", *modules, *names, ""])
        (tmp_path / f"doc_{name}.py").write_text(prelude + block)
    config = tmp_path / "mypy.ini"
    # JAX is not analysed: no block uses it, and gymnasium's functional environments would
    # bring its 1,200 modules in (half of the check's time).
    config.write_text(
        "[mypy]\ncheck_untyped_defs = True\nignore_missing_imports = True\n"
        "[mypy-jax,jax.*,jaxlib,jaxlib.*]\nfollow_imports = skip\n"
    )
    out = subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(config), "--no-incremental", str(tmp_path)],
        cwd=tmp_path, capture_output=True, text=True, timeout=600,
    )
    assert out.returncode == 0, out.stdout + out.stderr
