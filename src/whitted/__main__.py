"""``python -m whitted`` runs the ``whitted`` program."""

from .program import main

main()
