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

from .case import Case, CaseError, case_from_dict, load_case
from .geometry import GridFrame, initial_state
from .properties import ICE, LATENT_HEAT, WATER, Phase, Properties
from .results import StefanResults, load_results
from .run import RunResult, run_case
from .solver import Air, EnthalpySolver, Faces, stability_limit
from .surfaces import extract_surfaces

__all__ = ["ICE", "LATENT_HEAT", "WATER", "Air", "Case", "CaseError", "EnthalpySolver", "Faces",
           "GridFrame", "Phase", "Properties", "RunResult", "StefanResults", "case_from_dict",
           "extract_surfaces", "initial_state", "load_case", "load_results", "run_case",
           "stability_limit"]
