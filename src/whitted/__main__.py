"""``python -m whitted`` runs the ``whitted`` program."""

from .cli.interrupt import install_process_handlers

install_process_handlers()  # first: a Ctrl-C while the modules load is one line, no traceback

from .program import main  # noqa: E402

main()
