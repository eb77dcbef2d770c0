"""Python packages of ROSMC, installed by catkin (catkin_python_setup in CMakeLists.txt).

Every ``rosmc_*`` package and subpackage is found automatically. Data files inside a package
(the YAML skill library in ``rosmc_server/config``, rviz configs, icons, Qt ``.ui`` files,
``py.typed``) are package data, so code that finds them next to its module works from the
source tree, a devel space and an install space alike.
"""

from pathlib import Path

from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import find_packages, setup

HERE = Path(__file__).resolve().parent
PACKAGES = find_packages(where=str(HERE), include=["rosmc_*"])
DATA_SUFFIXES = {
    ".yaml", ".yml", ".json", ".xml", ".rviz", ".ui", ".qss",
    ".png", ".svg", ".jpg", ".urdf", ".xacro", ".obj", ".stl", ".dae", ".mtl", ".mcap",
}  # fmt: skip
DATA_NAMES = {"py.typed"}


def package_data(package: str) -> list[str]:
    """Data files of ``package`` relative to it, including those in its non-package folders."""
    root = HERE.joinpath(*package.split("."))
    found = []
    for path in sorted(root.rglob("*")):
        rel = path.relative_to(root)
        if not path.is_file() or "__pycache__" in rel.parts:
            continue
        if path.suffix not in DATA_SUFFIXES and path.name not in DATA_NAMES:
            continue
        owner = ".".join([package, *rel.parts[:-1]])
        if owner != package and owner in PACKAGES:
            continue  # a subpackage lists it
        found.append(rel.as_posix())
    return found


setup(
    **generate_distutils_setup(
        packages=PACKAGES,
        package_data={name: files for name in PACKAGES if (files := package_data(name))},
    )
)
