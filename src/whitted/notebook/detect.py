"""Is this Python running in a notebook that shows widgets?

True in an IPython kernel (ipykernel's shell: JupyterLab, Notebook, VS Code, Colab, a kernel
run by nbclient) when ipywidgets is installed (the ``notebook`` extra). False in a terminal,
a script, plain IPython, the Spyder console (its kernel shows no widgets) and wherever the
extra is missing: there everything stays as it was (``Image._repr_png_``, no widgets).
``WHITTED_NOTEBOOK=0`` turns the widgets off in a notebook, ``=1`` forces them on.
"""

from __future__ import annotations

import importlib.util
import os
import sys

__all__ = ["in_notebook", "live_view", "widgets_installed"]


def widgets_installed() -> bool:
    """ipywidgets can be imported (without importing it)."""
    if "ipywidgets" in sys.modules:
        return True
    try:
        return importlib.util.find_spec("ipywidgets") is not None
    except (ImportError, ValueError):
        return False


def _kernel_shell() -> bool:
    ipython = sys.modules.get("IPython")
    if ipython is None:  # never imported: no IPython, so no kernel
        return False
    try:
        shell = ipython.get_ipython()
    except Exception:  # noqa: BLE001 - a broken IPython is no notebook
        return False
    if shell is None or getattr(shell, "kernel", None) is None:
        return False  # plain IPython in a terminal has no kernel
    if "spyder_kernels" in sys.modules:  # Spyder's console: a kernel whose frontend has no widgets
        return False
    zmqshell = sys.modules.get("ipykernel.zmqshell")
    return zmqshell is not None and isinstance(shell, zmqshell.ZMQInteractiveShell)


def in_notebook() -> bool:
    """Widgets can be shown here (see the module's docstring)."""
    forced = os.environ.get("WHITTED_NOTEBOOK", "").strip().lower()
    if forced in ("0", "false", "no", "off"):
        return False
    if not widgets_installed():
        return False
    if forced in ("1", "true", "yes", "on"):
        return True
    return _kernel_shell()


def live_view(live: bool | None) -> bool:
    """Whether a call shows its widgets: ``live`` None -> :func:`in_notebook`; True needs the
    ``notebook`` extra (one-line :class:`~whitted.WhittedError` without it)."""
    if live is None:
        return in_notebook()
    if live and not widgets_installed():
        from ..errors import WhittedError

        raise WhittedError("live=True needs ipywidgets: pip install 'whitted[notebook]'")
    return bool(live)
