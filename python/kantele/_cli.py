"""The `kantele` command as the package installs it (`[project.scripts]`): the same command line
as the Rust binary's (`kantele_cli::run_command_line`), compiled into the extension module, so
one `pip install` gives the module and the command. `python -m kantele` runs it too."""

import sys
import warnings


def main() -> None:
    """Runs `kantele` with this process's arguments and exits with its status."""
    with warnings.catch_warnings():
        # The command reports KANTELE_ISA problems itself, once, as the binary does.
        warnings.simplefilter("ignore", RuntimeWarning)
        from kantele._kantele import _run_cli
    try:
        status = _run_cli(["kantele", *sys.argv[1:]])
    except KeyboardInterrupt:
        # Ctrl-C while the command ran: it stopped cleanly and reported it; Python's own
        # handler saw the signal too and raises on return.
        status = 130
    sys.exit(status)
