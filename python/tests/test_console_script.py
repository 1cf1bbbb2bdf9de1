"""The package's `kantele` command (the console script pip installs, and `python -m kantele`) is
the Rust binary's command line: the same pictures byte for byte, the same errors and statuses."""

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(sys.executable).parent / "kantele"


def installed_command():
    """The console script next to this interpreter, which `pip install ./python` writes."""
    if not SCRIPT.is_file():
        pytest.fail(f"{SCRIPT} is missing: the package installs a `kantele` command")
    return [str(SCRIPT)]


@pytest.mark.parametrize("how", ["script", "module"])
def test_the_package_command_draws_what_the_binary_draws(tmp_path, cli, how):
    command = installed_command() if how == "script" else [sys.executable, "-m", "kantele"]
    args = ["render", "--builtin", "teapot", "--size", "96x64", "--msaa", "4", "-q"]
    mine = subprocess.run([*command, *args, "-o", str(tmp_path / "a.png")],
                          capture_output=True, text=True)
    theirs = subprocess.run([cli, *args, "-o", str(tmp_path / "b.png")],
                            capture_output=True, text=True)
    assert mine.returncode == 0 and theirs.returncode == 0, mine.stderr + theirs.stderr
    assert mine.stderr == "" == theirs.stderr
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()


def test_the_package_command_reports_errors_as_the_binary_does(tmp_path, cli):
    args = ["render", "--bogus"]
    mine = subprocess.run([*installed_command(), *args], capture_output=True, text=True)
    theirs = subprocess.run([cli, *args], capture_output=True, text=True)
    assert mine.returncode == theirs.returncode == 2
    assert mine.stderr == theirs.stderr
    assert mine.stderr.endswith("(see kantele render --help)\n"), mine.stderr
    version = subprocess.run([*installed_command(), "--version"], capture_output=True, text=True)
    assert version.returncode == 0 and version.stdout.startswith("kantele "), version
