"""Shared helpers of the Python tests: where the repository, the reference scenes and the
`kantele` command are, and the `KANTELE_REQUIRE` rule (a named dependency that is missing fails
instead of skipping)."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def required(name: str) -> bool:
    """Whether `KANTELE_REQUIRE` (comma- or space-separated) names `name`."""
    return name in os.environ.get("KANTELE_REQUIRE", "").replace(",", " ").split()


def skip_or_fail(name: str, reason: str):
    """Skips the test with `reason`, or fails it when `KANTELE_REQUIRE` names `name`."""
    if required(name):
        pytest.fail(f"{reason} (KANTELE_REQUIRE names '{name}')")
    pytest.skip(reason)


def shared_root() -> Path:
    """The shared test data (`scenes/`, `realworld/`): `KANTELE_SHARED` when it is set and not
    empty, else `../shared` beside the repository (docs/rendering-rules.md, "Reference scenes");
    the same folder as `kantele_testkit::shared_root` in the Rust tests."""
    return Path(os.environ.get("KANTELE_SHARED") or REPO.parent / "shared")


@pytest.fixture(scope="session")
def scenes_dir() -> Path:
    """The reference scenes, `$KANTELE_SHARED/scenes`."""
    d = shared_root() / "scenes"
    if not d.is_dir():
        skip_or_fail("scenes", f"{d} is absent")
    return d


@pytest.fixture(scope="session")
def cli() -> str:
    """The `kantele` binary cargo built (release or debug), building it when there is none."""
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for profile in ("release", "debug"):
        exe = target / profile / "kantele"
        if exe.is_file():
            return str(exe)
    if shutil.which("cargo") is None:
        skip_or_fail("cli", "no kantele binary in target/ and no cargo to build one")
    subprocess.run(["cargo", "build", "-p", "kantele-cli"], cwd=REPO, check=True)
    return str(target / "debug" / "kantele")


def _skip_reason(report) -> str:
    longrepr = report.longrepr
    reason = longrepr[2] if isinstance(longrepr, tuple) else str(longrepr)
    return " ".join(reason.removeprefix("Skipped: ").split())


def pytest_runtest_logreport(report):
    """Appends each skip to `$KANTELE_SKIP_LOG` (as the Rust tests' `kantele_testkit::skip`
    does), so that `.ci/test` sums up Rust and Python skips in one line."""
    log = os.environ.get("KANTELE_SKIP_LOG")
    if report.skipped and log:
        with open(log, "a", encoding="utf-8") as f:
            f.write(f"skipping {report.nodeid}: {_skip_reason(report)}\n")


def pytest_terminal_summary(terminalreporter):
    """Ends every run with one line: what was skipped and why, or that nothing was."""
    skipped = terminalreporter.stats.get("skipped", [])
    if not skipped:
        terminalreporter.write_line("kantele: no Python test skipped")
        return
    reasons = {}
    for report in skipped:
        reason = _skip_reason(report)
        reasons[reason] = reasons.get(reason, 0) + 1
    listed = "; ".join(f"{why} ({n})" for why, n in sorted(reasons.items()))
    terminalreporter.write_line(f"kantele: {len(skipped)} Python test(s) skipped: {listed}")
