"""Find the project's PyPI packages when a node is started outside ``env.sh``.

ROSMC needs a few packages that Debian's ROS 1 does not ship (pybullet, mcap, rosbags;
``requirements.txt``). ``make setup`` installs them into ``.venv`` in the checkout. In a
catkin or colcon workspace, ``rosrun`` / ``roslaunch`` start the entry scripts with
``/usr/bin/python3``, which does not see that venv. Every entry script therefore calls
:func:`use_project_venv` first: it puts the venv's ``site-packages`` on ``sys.path``, in front
of Debian's ``dist-packages`` (where the venv's own interpreter has it), when it finds one:

1. ``$ROSMC_VENV`` (a venv folder), for install spaces and custom layouts;
2. ``.venv`` in the source checkout this package is imported from (devel spaces and
   ``source env.sh``).

Nothing changes when the interpreter already runs inside a venv or none is found. An entry
script started through :func:`run_entry_point` then ends with one sentence that names the
missing package and the two ways to install it, instead of a traceback.
"""

from __future__ import annotations

import contextlib
import faulthandler
import importlib
import io
import os
import signal
import sys
import types
from collections.abc import Callable
from pathlib import Path
from typing import cast

VENV_VARIABLE = "ROSMC_VENV"
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports a program Ctrl-C stopped
OWN_PACKAGE_PREFIX = "rosmc"
# Import names whose PyPI name differs (requirements.txt has the PyPI names).
PYPI_NAMES = {"mcap_ros1": "mcap-ros1-support", "yaml": "PyYAML"}


def site_packages(venv: Path) -> Path:
    """The ``site-packages`` folder of ``venv`` for the running interpreter's version."""
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    return venv / "lib" / version / "site-packages"


def candidate_venvs(environ: dict[str, str] | None = None) -> list[Path]:
    """Venv folders to try, in order: ``$ROSMC_VENV``, then ``.venv`` beside each source root."""
    environ = dict(os.environ) if environ is None else environ
    found: list[Path] = []
    if environ.get(VENV_VARIABLE):
        found.append(Path(environ[VENV_VARIABLE]))
    # In a devel space the package's __path__ lists the source folder too (catkin's relay).
    package_dirs = [Path(entry) for entry in _package_path()]
    found.extend(directory.resolve().parent / ".venv" for directory in package_dirs)
    return found


def use_project_venv(environ: dict[str, str] | None = None) -> Path | None:
    """Put the first venv found on ``sys.path`` before Debian's packages; return its folder."""
    if sys.prefix != sys.base_prefix:
        return None  # already inside a venv (env.sh, .venv/bin/python)
    for venv in candidate_venvs(environ):
        packages = site_packages(venv)
        if packages.is_dir():
            _insert_before_dist_packages(str(packages), sys.path)
            return venv
    return None


def _insert_before_dist_packages(entry: str, path: list[str]) -> None:
    """Insert ``entry`` into ``path`` just before the first ``dist-packages`` folder."""
    if entry in path:
        return
    debian = [i for i, item in enumerate(path) if item.rstrip("/").endswith("dist-packages")]
    path.insert(debian[0] if debian else len(path), entry)


def _package_path() -> list[str]:
    import rosmc_server

    return list(getattr(rosmc_server, "__path__", []))


def defer_functions(module: str, names: tuple[str, ...]) -> None:
    """Stand in for ``module`` with its functions ``names``, each importing it when called.

    For a dependency's module that is costly to import and that its importers only take
    functions from (``from module import name``), rarely calling them: the module is then
    imported at the first call, not at start. Does nothing if ``module`` is imported already.
    """
    if module in sys.modules:
        return
    stand_in = types.ModuleType(module, f"Stands in for {module} until it is needed.")

    def real() -> types.ModuleType:
        if sys.modules.get(module) is stand_in:
            del sys.modules[module]
        return importlib.import_module(module)

    for name in names:

        def call(*args: object, _name: str = name, **kwargs: object) -> object:
            return getattr(real(), _name)(*args, **kwargs)

        setattr(stand_in, name, call)
    sys.modules[module] = stand_in


def run_entry_point(
    module: str,
    unused: tuple[str, ...] = (),
    deferred: dict[str, tuple[str, ...]] | None = None,
) -> int:
    """Run ``module.main()`` with the project's venv; a missing dependency ends in one sentence.

    ``SIGUSR1`` makes the process print every thread's stack (to diagnose a stuck node);
    Ctrl-C while the program is still importing ends it quietly with status 130.

    What a ``scripts/`` entry script calls. A module of this project that is missing is a
    broken install and raises as usual. ``unused`` names optional modules that a
    dependency imports when they are installed but this program never needs: they are
    kept out (their import raises ImportError, which such a dependency handles).
    ``deferred`` maps a dependency's modules to the functions taken from them, imported
    only when one is called (see :func:`defer_functions`).
    """
    for name in unused:
        sys.modules.setdefault(name, None)  # type: ignore[arg-type]
    for name, functions in (deferred or {}).items():
        defer_functions(name, functions)
    # `kill -USR1 <pid>` prints every thread's stack to the node's stderr (its log): what a
    # node that stopped answering is doing, without stopping it.
    with contextlib.suppress(io.UnsupportedOperation, ValueError):  # stderr is no file
        faulthandler.register(signal.SIGUSR1, all_threads=True)
    use_project_venv()
    try:
        main = cast(Callable[[], int], importlib.import_module(module).main)
        return main()
    except ModuleNotFoundError as error:
        top = (error.name or "").partition(".")[0]
        if not top or top.startswith(OWN_PACKAGE_PREFIX):
            raise
        print(missing_dependency_message(top, Path(sys.argv[0]).name), file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # Ctrl-C before the program took it over (while importing)
        return EXIT_INTERRUPTED


def missing_dependency_message(name: str, program: str) -> str:
    """One sentence: which module is missing and how to install it (rosdep or a venv)."""
    pypi = PYPI_NAMES.get(name, name)
    return (
        f"{program}: the Python module '{name}' (PyPI package {pypi}) is missing; install "
        "ROSMC's dependencies with `rosdep install --from-paths src --ignore-src -y` in the "
        f"workspace, or set {VENV_VARIABLE} to a venv made from requirements.txt "
        "(`make setup` makes .venv in the checkout)."
    )
