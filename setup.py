"""Python packages of ROSMC, installed by catkin (catkin_python_setup)."""

from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(
    **generate_distutils_setup(
        packages=[],
        package_dir={},
    )
)
