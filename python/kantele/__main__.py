"""`python -m kantele ARGS`: the `kantele` command (see `kantele._cli`)."""

from kantele._cli import main

main()
