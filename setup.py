"""The wheel carries the example scenes (``examples/``, with their models and textures) and
the benchmark scenes (``benchmarks/``) as package data, under ``whitted/examples/`` and
``whitted/benchmarks/``: an installed whitted renders the examples by name
(``whitted render glass_cube``), copies them out (``whitted examples DIR``) and runs
``whitted bench``. Everything else is in pyproject.toml."""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
#: folder of the checkout -> the files of it the wheel carries
SHIPPED = {
    "examples": ("*.toml", "stefan/*.toml", "models/*.obj", "models/*.mtl", "models/README.md",
                 "models/LICENSES/*", "models/cow/*", "textures/*.png",
                 "models/make_cones.py", "textures/make_textures.py"),  # what made them
    "benchmarks": ("*.toml", "models/*.obj", "povray_checks/*.toml"),
}


class BuildWithScenes(build_py):
    def run(self) -> None:
        super().run()
        for folder, patterns in SHIPPED.items():
            target = Path(self.build_lib) / "whitted" / folder
            for pattern in patterns:
                for source in sorted((HERE / folder).glob(pattern)):
                    if source.is_file():
                        dest = target / source.relative_to(HERE / folder)
                        dest.parent.mkdir(parents=True, exist_ok=True)
                        shutil.copyfile(source, dest)


setup(cmdclass={"build_py": BuildWithScenes})
