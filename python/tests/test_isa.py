"""`KANTELE_ISA` in Python: the level renders use is `kantele.isa()`, and a value that names no
level, or one this CPU lacks, is a `RuntimeWarning` at import (the `kantele` command's message),
never silently ignored."""

import os
import platform
import subprocess
import sys

import numpy as np

import kantele

LEVELS = {"avx512", "avx2", "sse41", "sse2", "neon", "scalar"}
PROBE = "import kantele; print(kantele.isa())"


def run_with_isa(value):
    """`kantele.isa()` and the warnings of a fresh interpreter importing kantele with
    `KANTELE_ISA=value` (unset when None)."""
    env = dict(os.environ)
    env.pop("KANTELE_ISA", None)
    if value is not None:
        env["KANTELE_ISA"] = value
    done = subprocess.run(
        [sys.executable, "-W", "always", "-c", PROBE],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return done.stdout.strip(), done.stderr


def test_isa_is_a_level_and_renders():
    assert kantele.isa() in LEVELS
    out = kantele.Scene.builtin("cube").render(size=(32, 24))
    assert out["color"].shape == (24, 32, 4) and np.any(out["color"][..., 3] > 0)


def test_scalar_is_honoured_without_warning():
    level, stderr = run_with_isa("scalar")
    assert level == "scalar"
    assert "KANTELE_ISA" not in stderr


def test_unknown_level_warns_and_uses_the_best():
    best, _ = run_with_isa(None)
    level, stderr = run_with_isa("mmx")
    assert level == best
    assert "RuntimeWarning: KANTELE_ISA: unknown instruction set `mmx` (expected one of" in stderr
    assert stderr.count("KANTELE_ISA") == 1
    assert f"; using {best}" in stderr


def test_unsupported_level_warns_and_uses_the_best():
    best, _ = run_with_isa(None)
    foreign = "neon" if platform.machine().lower() in ("x86_64", "amd64") else "avx2"
    level, stderr = run_with_isa(foreign)
    assert level == best
    assert (
        f"RuntimeWarning: KANTELE_ISA={foreign}: this CPU does not support it; using {best}"
        in stderr
    )
