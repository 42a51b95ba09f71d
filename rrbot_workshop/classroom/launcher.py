"""The course's two commands, ``start`` and ``test``, on every platform, with the standard library only.

``python workshop.py start|test`` (or ``./workshop start|test``, or ``python -m rrbot_workshop start|test`` once
installed) runs this module. It must work before anything is installed, so it imports nothing outside the standard
library and nothing from the package.

How the learner's work and the course material are kept apart:

* The learner edits the files in ``exercises/`` in place, in JupyterLab's file browser or any editor. Nothing else in
  the course writes there (``rrbot-workshop reset`` backs the files up first).
* The learner runs the notebooks from ``my_notebooks/``, git-ignored copies of ``notebooks/`` made by ``start``.
  Saving a notebook (outputs, edits) never touches a tracked file, and a ``git pull`` of new course material never
  meets a conflict there. When a course notebook changed since the copy was made, ``start`` puts the learner's copy
  in ``my_notebooks/backups/<time>/`` before refreshing it.
* ``test`` tests the course *as shipped*: the pristine exercises are taken from git (``HEAD``) into a temporary folder
  and used wherever a test needs the untouched exercises (``RRBOT_WORKSHOP_EXERCISES``), so it passes whatever the
  state of the learner's files.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time
import zipfile
from collections.abc import Iterator, Sequence
from pathlib import Path

__all__ = ["main", "SUPPORTED", "refresh_notebook_copies", "pristine_exercises", "planned_runs", "write_atomically",
           "move_aside", "make_folder", "clear_for_file", "unique_folder", "regular_file_bytes", "PARTIAL_SUFFIX",
           "ASIDE_SUFFIX", "PYTHON_ENV", "course_env"]

#: Python versions the course runs on (every pinned binary dependency ships wheels for them).
SUPPORTED = ((3, 11), (3, 12), (3, 13))
#: The kernel the notebooks name in their metadata (installed into the course's environment).
KERNEL_NAME, KERNEL_DISPLAY_NAME = "python3", "Python 3 (rrbot_workshop)"
EXERCISES_ENV = "RRBOT_WORKSHOP_EXERCISES"
_WINDOWS = os.name == "nt"


def _say(message: str) -> None:
    print(f"[rrbot_workshop] {message}", flush=True)


def _venv_python(venv: Path) -> Path:
    return venv / ("Scripts/python.exe" if _WINDOWS else "bin/python")


def _venv_bin(venv: Path) -> Path:
    return venv / ("Scripts" if _WINDOWS else "bin")


def _supported(version: tuple[int, int]) -> bool:
    return version in SUPPORTED


def _stamp(root: Path) -> str:
    return hashlib.sha256((root / "pyproject.toml").read_bytes()).hexdigest()


#: The Python of an environment already set up from the same ``pyproject.toml``, used instead of the course's own
#: ``.venv`` (CI tests a student copy it exported with the environment it installed): the course's folder then comes
#: first on ``PYTHONPATH``, so its own ``rrbot_workshop`` is the one imported, and ``setup`` checks that it is.
PYTHON_ENV = "RRBOT_WORKSHOP_PYTHON"


def _given_environment(root: Path, python: Path) -> Path:
    """The Python named by :data:`PYTHON_ENV`, once it is shown to be set up from this course's pyproject.toml and to
    import this course's package."""
    stamp = python.parent.parent / ".installed"
    if not python.is_file() or not stamp.is_file() or stamp.read_text().strip() != _stamp(root):
        raise SystemExit(f"${PYTHON_ENV} names {python}, which is not an environment set up from this course's "
                         "pyproject.toml (its .installed stamp differs); unset it to set up .venv here")
    found = subprocess.run([str(python), "-c", "import rrbot_workshop; print(rrbot_workshop.__file__)"], cwd=root,
                           env=course_env(root, dict(os.environ)), capture_output=True, text=True)  # as the runs
    if found.returncode != 0 or not Path(found.stdout.strip()).resolve().is_relative_to(root):
        raise SystemExit(f"${PYTHON_ENV}: {python} imports rrbot_workshop from {found.stdout.strip() or '?'}, not from "
                         f"{root}")
    return python


def course_env(root: Path, env: dict[str, str]) -> dict[str, str]:
    """``env`` for the course's processes: with :data:`PYTHON_ENV` set, the course's folder first on ``PYTHONPATH``."""
    if env.get(PYTHON_ENV):
        env = {**env, "PYTHONPATH": os.pathsep.join(p for p in (str(root), env.get("PYTHONPATH", "")) if p)}
    return env


def setup(root: Path) -> Path:
    """Create ``.venv`` and install the course into it on first use (or when pyproject.toml changed); or use the
    environment :data:`PYTHON_ENV` names.

    Returns:
        The environment's Python.
    """
    if os.environ.get(PYTHON_ENV):
        return _given_environment(root, Path(os.environ[PYTHON_ENV]))
    venv = root / ".venv"
    python = _venv_python(venv)
    stamp_file = venv / ".installed"
    want = _stamp(root)
    if python.exists() and stamp_file.exists() and stamp_file.read_text().strip() == want:
        return python
    if not _supported(sys.version_info[:2]):
        versions = ", ".join(f"{a}.{b}" for a, b in SUPPORTED)
        raise SystemExit(f"rrbot_workshop needs Python {versions}; this is {sys.version.split()[0]} ({sys.executable}).")
    if not python.exists():
        _say(f"creating .venv with Python {sys.version.split()[0]}")
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    _say("installing rrbot_workshop and its pinned dependencies into .venv (the first time takes a few minutes)")
    quiet = {"stdout": subprocess.PIPE, "stderr": subprocess.STDOUT, "text": True}
    steps = [
        [str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--upgrade", "pip"],
        [str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "-e", f"{root}[dev]"],
        [str(python), "-m", "ipykernel", "install", "--prefix", str(venv), "--name", KERNEL_NAME,
         "--display-name", KERNEL_DISPLAY_NAME],
    ]
    for step in steps:
        result = subprocess.run(step, **quiet)  # type: ignore[call-overload]
        if result.returncode != 0:
            print(result.stdout, file=sys.stderr)
            raise SystemExit(f"set-up failed: {' '.join(step[:5])} ... (exit {result.returncode})")
    _quiet_jupyterlab(venv)
    stamp_file.write_text(want)
    _say("set-up done")
    return python


def _quiet_jupyterlab(venv: Path) -> None:
    """No news and no update prompt in the course's JupyterLab (its settings overrides, inside .venv)."""
    settings = venv / "share" / "jupyter" / "lab" / "settings"
    settings.mkdir(parents=True, exist_ok=True)
    overrides = {"@jupyterlab/apputils-extension:notification": {"checkForUpdates": False, "fetchNews": "false"}}
    (settings / "overrides.json").write_text(json.dumps(overrides, indent=2) + "\n")


# --------------------------------------------------------------------------------------------- writing learners' folders
# A course command that writes into a learner's folder (``my_notebooks/``, a hub workspace) must leave every file
# either as it was or as it should be, whenever the process is killed; it writes through no link, and whatever stands
# where the course needs a file or a folder is the learner's: it is kept beside, never removed.

#: The suffix of the hidden file a new version is written to, beside its target, before it is renamed over it.
PARTIAL_SUFFIX = ".rrbot-partial"
#: The suffix a learner's file or folder takes when the course needs its place (``launch`` -> ``launch.yours``).
ASIDE_SUFFIX = ".yours"
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_BINARY", 0)


def _kind(mode: int) -> str:
    if stat.S_ISLNK(mode):
        return "link"
    return "folder" if stat.S_ISDIR(mode) else "file" if stat.S_ISREG(mode) else "special file"


def write_atomically(path: Path, data: bytes, mode: int = 0o644) -> None:
    """Write ``data`` to ``path`` so that ``path`` holds its old content or the new one, never a part of it.

    The bytes go to a hidden file beside ``path`` (``.<name>.rrbot-partial``; one left by a killed write is reused),
    which is then renamed over ``path``. A link at ``path`` is replaced by the file, never written through.

    Args:
        path: The file; its folder must exist.
        data: The new content.
        mode: Permission bits of a new file (the umask applies).
    """
    name = path.name if len(path.name.encode()) < 200 else hashlib.sha256(path.name.encode()).hexdigest()[:32]
    for n in range(1, 1000):
        partial = path.with_name(f".{name}{'' if n == 1 else f'.{n}'}{PARTIAL_SUFFIX}")
        try:
            found = os.lstat(partial)
        except FileNotFoundError:
            break
        if stat.S_ISREG(found.st_mode):  # left by a write that was killed: ours to reuse
            os.unlink(partial)
            break
    fd = os.open(partial, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW, mode)
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
    except BaseException:
        os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(partial)
        raise
    os.close(fd)
    os.replace(partial, path)


def aside_name(path: Path) -> Path:
    """A free name beside ``path`` for the learner's version of it: ``<name>.yours``, else ``<name>.yours-2``, ..."""
    for n in range(1, 10_000):
        candidate = path.with_name(f"{path.name}{ASIDE_SUFFIX}{'' if n == 1 else f'-{n}'}")
        if not os.path.lexists(candidate):
            return candidate
    raise FileExistsError(f"no free name beside {path}")


def move_aside(path: Path, root: Path, notes: list[str], needed: str) -> Path:
    """Rename what stands at ``path`` (a learner's file, folder or link) to a free name beside it and say so in
    ``notes``, in one line naming it (``needed``: what the course puts there, "a file" or "a folder").

    Returns:
        Where the learner's version is now.
    """
    kind = _kind(os.lstat(path).st_mode)
    aside = aside_name(path)
    os.rename(path, aside)
    notes.append(f"{_shown(path, root)} was a {kind} where the course now has {needed}: yours is kept beside it as "
                 f"{aside.name}")
    return aside


def _shown(path: Path, root: Path) -> str:
    try:
        return path.relative_to(root).as_posix()
    except ValueError:
        return str(path)


def make_folder(root: Path, rel: str, notes: list[str]) -> Path:
    """``root/rel`` as a real folder, made where missing; a file or link on the way (the learner's) is moved aside.

    ``root`` itself must be a folder. Nothing is ever written through a link: a link where a folder is needed is
    renamed, and its target left alone.
    """
    path = root
    for part in Path(rel).parts:
        path = path / part
        try:
            mode = os.lstat(path).st_mode
        except FileNotFoundError:
            os.mkdir(path)
            continue
        if not stat.S_ISDIR(mode):
            move_aside(path, root, notes, "a folder")
            os.mkdir(path)
    return path


def clear_for_file(root: Path, rel: str, notes: list[str]) -> Path:
    """``root/rel`` ready to be written as a file: its folders made (see :func:`make_folder`) and anything but a
    regular file at its place (a folder, a link, a FIFO: the learner's) moved aside."""
    path = make_folder(root, str(Path(rel).parent), notes) / Path(rel).name
    with contextlib.suppress(FileNotFoundError):
        if not stat.S_ISREG(os.lstat(path).st_mode):
            move_aside(path, root, notes, "a file")
    return path


def unique_folder(base: Path) -> Path:
    """Make a new folder, ``base`` or, when that name is taken, ``base_2``, ``base_3``, ...: two backups made in the
    same second never share one. ``base``'s parent must exist."""
    for n in range(1, 10_000):
        candidate = base if n == 1 else base.with_name(f"{base.name}_{n}")
        try:
            os.mkdir(candidate)
            return candidate
        except FileExistsError:
            continue
    raise FileExistsError(f"no free folder name for {base}")


def regular_file_bytes(path: Path, limit: int) -> bytes | None:
    """The content of ``path`` if it is a regular file (not a link, FIFO or device) of at most ``limit`` bytes;
    None otherwise. Never blocks: the file is opened non-blocking and checked again once open."""
    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return None
        fd = os.open(path, os.O_RDONLY | _NOFOLLOW | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or info.st_size > limit:
            return None
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        return b"".join(chunks) if size <= limit else None
    except OSError:
        return None
    finally:
        os.close(fd)


# --------------------------------------------------------------------------------------------- notebook copies

#: The largest notebook index read [bytes] (one line per notebook).
_INDEX_MAX_BYTES = 1 << 20


def _read_index(index_file: Path, lines: list[str], root: Path) -> dict[str, str] | None:
    """The index of the copies made (notebook name -> sha256 of the course's notebook copied), or None (and a line
    in ``lines``) when it is damaged."""
    if not os.path.lexists(index_file):
        return {}
    data = regular_file_bytes(index_file, _INDEX_MAX_BYTES)
    try:
        index = json.loads(data.decode()) if data is not None else None
    except (ValueError, UnicodeDecodeError):
        index = None
    if isinstance(index, dict) and all(isinstance(k, str) and isinstance(v, str) for k, v in index.items()):
        return index
    lines.append(f"{_shown(index_file, root)} was damaged: it is rebuilt, and each notebook copy is refreshed with "
                 "your copy kept in my_notebooks/backups/")
    return None


def refresh_notebook_copies(root: Path, now: float | None = None, notes: list[str] | None = None) -> list[str]:
    """Copy ``notebooks/*.ipynb`` to ``my_notebooks/``; never overwrite a learner's copy without a backup.

    A copy is made when it is missing. When the course's notebook changed since the copy was made, the learner's copy
    is moved to ``my_notebooks/backups/<YYYYmmdd-HHMMSS>/`` first (``<YYYYmmdd-HHMMSS>_2/`` when a backup of the same
    second exists) and a fresh copy takes its place. Every copy and the index of what was copied
    (``my_notebooks/.sources.json``) is written atomically (:func:`write_atomically`), so a start that is killed
    leaves each notebook whole; a damaged index is rebuilt. A file or link where a folder is needed is kept beside it
    (:func:`make_folder`).

    Args:
        root: The course folder (a clone, or a learner's workspace).
        now: Time used in the backup folder's name [s since the epoch]; default now.
        notes: Where a line goes for each problem met and dealt with (a damaged index, a learner's file where a
            folder is needed); default the returned lines.

    Returns:
        One line per notebook copied or refreshed (and per problem met, without ``notes``), for the console.
    """
    lines: list[str] = []
    problems = lines if notes is None else notes
    source = root / "notebooks"
    target = make_folder(root, "my_notebooks", problems)
    index_file = clear_for_file(root, "my_notebooks/.sources.json", problems)
    found = _read_index(index_file, problems, root)
    index, rewrite = (found, not os.path.lexists(index_file)) if found is not None else ({}, True)
    stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(now))
    backup: Path | None = None
    for notebook in sorted(source.glob("[0-9][0-9]_*.ipynb")):
        copy = target / notebook.name
        data = notebook.read_bytes()
        digest = hashlib.sha256(data).hexdigest()
        try:
            mode: int | None = os.lstat(copy).st_mode
        except FileNotFoundError:
            mode = None
        if mode is not None and stat.S_ISREG(mode) and index.get(notebook.name) == digest:
            continue
        if mode is not None:
            if backup is None:
                backup = unique_folder(make_folder(root, "my_notebooks/backups", problems) / stamp)
            os.rename(copy, backup / notebook.name)
            why = "the course updated it" if stat.S_ISREG(mode) else f"a {_kind(mode)} stood in its place"
            lines.append(f"{notebook.name}: {why}; your copy is in my_notebooks/backups/{backup.name}/")
        else:
            lines.append(f"{notebook.name}: copied to my_notebooks/")
        write_atomically(copy, data)
        index[notebook.name] = digest
        rewrite = False
        write_atomically(index_file, (json.dumps(index, indent=1, sort_keys=True) + "\n").encode())
    if rewrite:
        write_atomically(index_file, (json.dumps(index, indent=1, sort_keys=True) + "\n").encode())
    return lines


# --------------------------------------------------------------------------------------------- pristine exercises


@contextlib.contextmanager
def pristine_exercises(root: Path) -> Iterator[Path | None]:
    """The ``exercises/`` folder as committed at ``HEAD``, extracted to a temporary folder.

    Yields None (and the working tree is used) when the course is not a git checkout or git is missing.
    """
    if not (root / ".git").exists() or shutil.which("git") is None:
        yield None
        return
    result = subprocess.run(["git", "archive", "--format=zip", "HEAD", "exercises"], cwd=root, capture_output=True)
    if result.returncode != 0:
        _say(f"git archive failed ({result.stderr.decode(errors='replace').strip()}); testing the working tree")
        yield None
        return
    with tempfile.TemporaryDirectory(prefix="rrbot_pristine_") as folder:
        zipfile.ZipFile(io.BytesIO(result.stdout)).extractall(folder)
        yield Path(folder) / "exercises"


# --------------------------------------------------------------------------------------------- commands


#: What JupyterLab's file browser does not list for a learner: the tracked notebooks (learners open their copies in
#: my_notebooks/), backups, caches, and the solutions (``./workshop start --show-solutions`` lists them).
HIDDEN = ("__pycache__", "*.pyc", "*.pyo", ".DS_Store", "*~", "notebooks", "backups", "solutions")


def jupyterlab_command(python: Path, root: Path, show_solutions: bool = False) -> list[str]:
    """The JupyterLab command of ``start``: on 127.0.0.1, at the course's root, opening the learner's intro."""
    from rrbot_workshop.classroom.kernels import server_args

    hidden = [g for g in HIDDEN if not (show_solutions and g == "solutions")]
    return [
        str(python), "-m", "jupyterlab", "--ip=127.0.0.1", f"--ServerApp.root_dir={root}",
        "--LabApp.default_url=/lab/tree/my_notebooks/00_intro.ipynb",
        f"--ContentsManager.hide_globs={hidden!r}", *server_args(),
    ]


def start(root: Path, args: Sequence[str]) -> int:
    """Set up, refresh ``my_notebooks/`` and run JupyterLab on 127.0.0.1 at the course's root.

    ``--show-solutions`` (an instructor's option, taken out of ``args``) lists ``solutions/`` in the file browser.
    """
    python = setup(root)
    for line in refresh_notebook_copies(root):
        _say(line)
    show_solutions = "--show-solutions" in args
    args = [a for a in args if a != "--show-solutions"]
    env = course_env(root, dict(os.environ))
    env["PATH"] = str(_venv_bin(python.parent.parent)) + os.pathsep + env.get("PATH", "")  # rrbot-workshop in the terminal
    env.setdefault("RRBOT_WORKSHOP_TRACK", "exercises")
    command = jupyterlab_command(python, root, show_solutions)
    if not _WINDOWS and hasattr(os, "geteuid") and os.geteuid() == 0:
        command.append("--allow-root")  # containers and CI machines often run as root
    if _WINDOWS:
        return subprocess.call([*command, *args], env=env, cwd=root)
    os.chdir(root)
    os.execve(command[0], [*command, *args], env)  # JupyterLab takes this process's place: signals reach it directly


def _pytest(python: Path, args: Sequence[str], env: dict[str, str], root: Path) -> int:
    code = subprocess.call([str(python), "-m", "pytest", *args], env=env, cwd=root)
    if code == 5:
        print("No tests were collected: failing.", file=sys.stderr)
        return 1
    return code


def _withheld_notebooks(root: Path) -> list[str]:
    """Notebooks a copy made with ``--withhold-references`` runs without comparing (its ``WITHHELD.json``, see
    ``rrbot_workshop.course.grading.references``: this module uses the standard library only)."""
    try:
        data = json.loads((root / "WITHHELD.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    return [str(n) for n in data.get("notebooks", [])] if isinstance(data, dict) else []


def _workers(python: Path) -> list[str]:
    """pytest-xdist's options for one worker per core (none where it is not installed: the tests then run in one)."""
    cores = os.cpu_count() or 1
    found = subprocess.run([str(python), "-c", "import xdist"], capture_output=True).returncode == 0
    # a whole file to a worker (its module fixtures made once), handed out in the order collected: the tests' conftest
    # puts the longest files first (tests/unit/scheduling.py), so no core works alone at the end
    return ["-n", str(cores), "--dist", "loadfile", "--no-loadscope-reorder"] if found and cores > 1 else []


def read_durations(path: Path) -> dict[str, float]:
    """File -> seconds a worker spent on it in a measured run (``tests/unit/durations.json``, see the tests'
    ``scheduling.py``); empty if the file is missing or unreadable."""
    try:
        seconds = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    if not isinstance(seconds, dict):
        return {}
    return {str(k): float(v) for k, v in seconds.items() if isinstance(v, (int, float))}


def _longest_first(root: Path, files: list[str]) -> list[str]:
    """``files`` in order of their measured seconds, longest first: a run of notebooks alone hands them out in the
    order given."""
    measured = read_durations(root / "tests" / "unit" / "durations.json")
    return sorted(files, key=lambda name: -measured.get(name, 0.0))


def _tally(report: Path) -> tuple[int, int, int, int]:
    """(tests, failures and errors, skipped, passed) of one run's JUnit XML report; zeros when it is missing."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(report).getroot()
    except (OSError, ET.ParseError):
        return 0, 0, 0, 0
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    tests = sum(int(s.get("tests", 0)) for s in suites)
    failed = sum(int(s.get("failures", 0)) + int(s.get("errors", 0)) for s in suites)
    skipped = sum(int(s.get("skipped", 0)) for s in suites)
    return tests, failed, skipped, tests - failed - skipped


def planned_runs(root: Path, env: dict[str, str]) -> list[tuple[str, list[str], dict[str, str]]]:
    """The pytest runs of ``test``: (what it tests, the selection, its environment), in order.

    The library's tests with the notebooks compared exactly on the untouched exercises; the notebooks a copy without the
    library's references runs without comparing (its ``WITHHELD.json``); every notebook on the solutions track, where
    the course has ``solutions/``.
    """
    notebooks = sorted(str(p.relative_to(root)) for p in (root / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    lax = [n for n in notebooks if n in _withheld_notebooks(root)]
    exact = [n for n in notebooks if n not in lax]
    # kernels forked from a template, as a learner's on Linux; the solutions track's start as new processes
    exercises_env = {**env, "RRBOT_WORKSHOP_TRACK": "exercises", PROVISIONER_ENV: FORKED_KERNELS}
    # the stored outputs are what a learner sees on the untouched exercises: compared exactly
    runs = [("library, graders and notebooks (exercises, compared)", ["--nbval", "tests/unit", *exact], exercises_env)]
    if lax:
        runs.append(("notebooks without the withheld references (run, not compared)",
                     ["--nbval-lax", *_longest_first(root, lax)], exercises_env))
    if (root / "solutions").is_dir():  # the finished track must run top to bottom too (outputs differ)
        runs.append(("notebooks on the solutions track (run, not compared)",
                     ["--nbval-lax", *_longest_first(root, notebooks)], {**env, "RRBOT_WORKSHOP_TRACK": "solutions"}))
    return runs


#: Jupyter's variable naming the provisioner of kernels, and the course's (classroom/kernels.py; a test checks the name)
PROVISIONER_ENV, FORKED_KERNELS = "JUPYTER_DEFAULT_PROVISIONER_NAME", "rrbot-workshop-forked"

#: Folders the processes of a whole test command share work through: xacro expansions, each checked against the files
#: it read before it is used (``rrbot_workshop.description.xacro_cache.SHARED_ENV``), and grader files as pytest
#: rewrote them (``rrbot_workshop.course.grading.plugin.PYCACHE_ENV``). Named here, as this module imports only the
#: standard library; a test checks they are the same names.
SHARED_WORK_ENV = ("RRBOT_WORKSHOP_XACRO_CACHE", "RRBOT_WORKSHOP_GRADER_PYCACHE")


def test(root: Path, args: Sequence[str]) -> int:
    """Set up and run every test: library, graders, and every notebook on both tracks, on every core.

    The runs of :func:`planned_runs`, each spread over the cores by pytest-xdist, a test file (or notebook) per worker at
    a time. The count of every run is printed at the end.
    """
    python = setup(root)
    env = course_env(root, dict(os.environ))
    with pristine_exercises(root) as exercises, tempfile.TemporaryDirectory(prefix="rrbot_reports_") as reports:
        if exercises is not None:
            env[EXERCISES_ENV] = str(exercises)
        else:
            _say("not a git checkout: testing exercises/ as it is (a learner's work may fail the graders' tests)")
        if args:
            return _pytest(python, args, env, root)
        for name in SHARED_WORK_ENV:  # every run (and its notebook kernels and gradings) shares this work
            env.setdefault(name, str(Path(reports) / name.lower()))
        options = ["-p", "no:cacheprovider", "--nbval-current-env", "--nbval-sanitize-with", "notebooks/nbval_sanitize.cfg",
                   *_workers(python)]
        runs = planned_runs(root, env)
        codes, lines = [], []
        for index, (what, selection, run_env) in enumerate(runs):
            report = Path(reports) / f"run{index}.xml"
            codes.append(_pytest(python, [*options, f"--junit-xml={report}", *selection], run_env, root))
            tests, failed, skipped, passed = _tally(report)
            lines.append(f"{what}: {tests} tests, {passed} passed, {failed} failed, {skipped} skipped")
        for line in lines:
            _say(line)
        total = [sum(_tally(Path(reports) / f"run{i}.xml")[k] for i in range(len(runs))) for k in range(4)]
        _say(f"in all: {total[0]} tests, {total[3]} passed, {total[1]} failed, {total[2]} skipped")
    return next((code for code in codes if code != 0), 0)


#: The course tool's commands, run from the course's environment: ``./workshop grade 1`` in any terminal is
#: ``rrbot-workshop grade 1`` in JupyterLab's (where the environment is on the PATH).
TOOL_COMMANDS = ("grade", "progress", "tasks", "reset", "export", "lint", "class-report", "init", "bringup")

USAGE = ("usage: python workshop.py start [jupyterlab options] | test [pytest options] | "
         f"{{{','.join(TOOL_COMMANDS)}}} ... (the rrbot-workshop tool)")


def tool(root: Path, args: Sequence[str]) -> int:
    """Set up and run one ``rrbot-workshop`` command with the course's environment.

    It runs in the caller's folder with ``--course root``, so a relative path on the command line (``lint
    my_ws/src/robot/config/x.yaml``, ``--package-path ../ws``) means what it means in the caller's shell.
    """
    python = setup(root)
    return subprocess.call([str(python), "-m", "rrbot_workshop.cli", "--course", str(root), *args],
                           env=course_env(root, dict(os.environ)))


def main(argv: Sequence[str] | None = None, root: Path | None = None) -> int:
    """Run ``start``, ``test`` or a tool command for the course at ``root`` (default: the folder above the package)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    root = (root or Path(__file__).resolve().parents[2]).resolve()
    if argv and argv[0] in ("-h", "--help", "help"):
        print(USAGE)
        return 0
    if not argv or argv[0] not in ("start", "test", *TOOL_COMMANDS):
        print(USAGE, file=sys.stderr)
        return 2
    command, rest = argv[0], argv[1:]
    if command in TOOL_COMMANDS:
        return tool(root, argv)
    return start(root, rest) if command == "start" else test(root, rest)
