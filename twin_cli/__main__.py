"""`python -m twin_cli`: the `twin` command, as the background server launcher starts it."""

from twin_cli.cli.app import main

main()
