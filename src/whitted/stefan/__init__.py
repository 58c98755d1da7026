"""The Stefan problem: how a hollow piece of ice with water inside melts.

Physics only (fields and surfaces); it never imports the renderer. ``docs/stefan.md`` has the
equations, the properties and their sources, the method and the validation.

In Python::

    from whitted import stefan

    case = stefan.load_case("examples/stefan/hollow_ice.toml")
    result = stefan.run_case(case, "", "out/")            # what `whitted stefan run` does
    H, kind, cavity, frame = stefan.initial_state(case)   # or step it yourself
    solver = stefan.EnthalpySolver(H, kind, case.dx, case.properties,
                                   faces=case.solver_faces(),
                                   air=case.solver_air())
    solver.advance(600.0)
    outer, inner = stefan.extract_surfaces(solver.H, solver.kind, case.properties, frame)
    stefan.load_results("out/")      # the run's time series; plots itself in a notebook
"""

import importlib.util

#: what the solver needs beyond whitted's core: ``pip install 'whitted[stefan]'``
NEEDS = {"scipy": "SciPy", "skimage": "scikit-image", "matplotlib": "Matplotlib"}


def missing_packages() -> list[str]:
    """The names of the solver's packages that are not installed (none: it can run)."""
    return [name for module, name in NEEDS.items() if importlib.util.find_spec(module) is None]


if missing_packages():
    _names = missing_packages()
    raise ImportError(f"whitted's Stefan solver needs "
                      f"{', '.join(_names[:-1]) + ' and ' * (len(_names) > 1) + _names[-1]}, "
                      "which are not installed: install whitted[stefan] "
                      "(pip install 'whitted[stefan]')")

from .case import Case, CaseError, case_from_dict, load_case  # noqa: E402
from .geometry import GridFrame, initial_state  # noqa: E402
from .properties import ICE, LATENT_HEAT, WATER, Phase, Properties  # noqa: E402
from .results import StefanResults, load_results  # noqa: E402
from .run import RunResult, run_case  # noqa: E402
from .solver import Air, EnthalpySolver, Faces, stability_limit  # noqa: E402
from .surfaces import extract_surfaces  # noqa: E402

__all__ = ["ICE", "LATENT_HEAT", "WATER", "Air", "Case", "CaseError", "EnthalpySolver", "Faces",
           "GridFrame", "Phase", "Properties", "RunResult", "StefanResults", "case_from_dict",
           "extract_surfaces", "initial_state", "load_case", "load_results", "run_case",
           "stability_limit"]
