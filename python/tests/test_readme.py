"""The README's Python example runs as written, and is the example file shipped beside it."""

import re
import subprocess
import sys

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
