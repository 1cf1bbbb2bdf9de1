"""README.md's code runs as written: its Python blocks, and its shell blocks' `kantele` command
lines, in a folder holding the files they name (`readme_fixture`); the paths it names exist.
Its Rust block is a doctest of the `kantele` crate (`cargo test --doc -p kantele`). Shell lines of
other programs are listed in `NOT_RUN_HERE`, each with what runs it instead, so that a new block
has to be placed in one list or the other."""

import importlib.util
import os
import re
import subprocess
import sys

import pytest

import kantele  # noqa: F401  (the package under test must import before the blocks run)

from conftest import REPO, required
import readme_fixture

README = REPO / "README.md"

# Shell commands of the README that this test does not run, by their start, with the reason.
NOT_RUN_HERE = {
    ".ci/test": "the test command itself",
    "cargo install cargo-fuzz": "installs the fuzzing tool, which needs a nightly toolchain",
    "cargo install": "installs into the user's cargo folder; CI builds the same crate",
    "cargo build --release -p kantele-cli --features cuda": "needs a CUDA build; CI builds the "
    "feature and the GPU check runs on a GPU machine",
    "pip install": "CI's .ci/test installs the package the same way before these tests",
    "pip wheel": "CI's .ci/test builds the same wheel when it installs the package",
    "cargo +nightly fuzz": "needs a nightly toolchain; .ci/run fuzzes where one is installed",
    "kantele view": "opens a window until it is closed; crates/kantele-cli/tests/cli/view.rs "
    "drives the viewer",
    "kantele render scene.glb -o out.png --backend cuda": "needs an NVIDIA GPU",
    "kantele bench scene.glb --backends cpu,cuda": "needs an NVIDIA GPU",
}


def code_blocks(language: str):
    """(first line number, text) of every fenced block of `language`."""
    found, inside, start, lines = [], None, 0, []
    for number, line in enumerate(README.read_text(encoding="utf-8").splitlines(), 1):
        fence = re.match(r"^```(\w*)\s*$", line)
        if fence and inside is None:
            inside, start, lines = fence.group(1), number + 1, []
        elif line.startswith("```") and inside is not None:
            if inside == language:
                found.append((start, "\n".join(lines) + "\n"))
            inside = None
        elif inside is not None:
            lines.append(line)
    return found


def shell_commands():
    """Every command line of the shell blocks, `\\` continuations joined: (line, command)."""
    commands = []
    for start, text in code_blocks("sh"):
        pending, first = "", start
        for offset, line in enumerate(text.splitlines()):
            if not pending:
                first = start + offset
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            command = (pending + line).strip()
            pending = ""
            if command and not command.startswith("#"):
                commands.append((first, command))
    return commands


def not_run_reason(command: str):
    return next((why for start, why in NOT_RUN_HERE.items() if command.startswith(start)), None)


@pytest.fixture()
def readme_folder(tmp_path, cli, monkeypatch):
    """A folder with the README's files, `kantele` first on the PATH, as the working folder."""
    readme_fixture.write(tmp_path)
    bin_dir = tmp_path / ".bin"
    bin_dir.mkdir()
    (bin_dir / "kantele").symlink_to(cli)
    monkeypatch.setenv("PATH", f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_the_python_blocks_run(readme_folder):
    blocks = code_blocks("python")
    assert blocks, "README.md has no Python block"
    for start, text in blocks:
        exec(compile(text, f"README.md:{start}", "exec"), {"__name__": "readme"})
    assert (readme_folder / "model.png").is_file()


def test_the_shell_blocks_run(readme_folder):
    ran, not_run = 0, []
    for line, command in shell_commands():
        reason = not_run_reason(command)
        if reason is not None:
            not_run.append(f"README.md:{line} {command.split('#')[0].strip()}: {reason}")
            continue
        program = command.split()[0]
        if command.startswith("cargo run ") and " -p kantele-cli " in command:
            # The first picture: the command line cargo runs, with the binary the tests built.
            command = "kantele " + command.split(" -- ", 1)[1]
        elif command.startswith("python -m kantele.ray"):
            if importlib.util.find_spec("ray") is None:
                if required("ray"):
                    pytest.fail(f"README.md:{line}: Ray is not installed (KANTELE_REQUIRE names ray)")
                not_run.append(f"README.md:{line} {command}: Ray is not installed")
                continue
            command = command.replace("python ", f"{sys.executable} ", 1)
        elif program != "kantele":
            pytest.fail(f"README.md:{line}: `{command}` is neither run here nor in NOT_RUN_HERE")
        done = subprocess.run(["bash", "-c", command], capture_output=True, text=True,
                              timeout=600)
        assert done.returncode == 0, f"README.md:{line}: {command}\n{done.stderr}"
        ran += 1
    # Each skip names itself, so a README change that stops a line running shows.
    print(f"\nREADME shell lines run: {ran}; not run here: {len(not_run)}")
    for entry in not_run:
        print(f"  {entry}")
    assert ran >= 15, ran
    assert (readme_folder / "cube.png").is_file() and (readme_folder / "spin.gif").is_file()
    assert len(list(readme_folder.glob("out/*.png"))) == 2


def test_every_named_path_exists():
    text = README.read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)#\s]+)", text)
    quoted = re.findall(r"`((?:crates|docs|python|scripts|fuzz|\.ci)/[\w./-]*\w)`", text)
    paths = [p for p in links + quoted if not re.match(r"^[a-z]+:", p)]
    assert len(paths) > 10
    missing = sorted({p for p in paths if not (REPO / p).exists()})
    assert not missing, f"README.md names paths that do not exist: {missing}"
