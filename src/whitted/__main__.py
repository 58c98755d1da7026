"""``python -m whitted`` runs the command line."""

from .cli.main import main

main()
