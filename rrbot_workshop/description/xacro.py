"""Xacro processing without ROS: ``$(find <pkg>)`` and ``package://`` resolve through the package path.

The ``xacro`` package does the work. Two of its habits need care outside ROS:

* ``$(find pkg)`` asks ``ament_index_python`` for the package's share folder. We swap that lookup for one that
  searches the package path (:mod:`rrbot_workshop.description.packages`: the folders given to
  :func:`~rrbot_workshop.description.packages.use_package_path`, ``$RRBOT_WORKSHOP_PACKAGE_PATH``, then
  :func:`descriptions_root`), only while :func:`process_xacro` runs, then put the original back. A package found as
  a source tree gives a folder that looks like its installed ``share/<pkg>`` (its ``CMakeLists.txt`` install rules
  applied), so ``$(find pkg)/ros2_control/x.xacro`` finds ``<src>/description/ros2_control/x.xacro``.
* ``xacro.process`` calls ``sys.exit`` on errors; we drive ``xacro.process_file`` instead and turn every failure
  into a :class:`~rrbot_workshop.exceptions.DescriptionError` that names the file.

Xacro keeps module-level state (file stack, verbosity, substitution arguments); a lock serialises calls and every
piece of state we touch is restored afterwards.

An expansion is kept for the rest of the process with everything it read (the contents of every file, the folders
``$(find)`` gave, wildcard matches, environment variables; :mod:`rrbot_workshop.description.xacro_cache`): the same
file with the same arguments is expanded again only when one of them changed.
"""

from __future__ import annotations

import ast
import errno
import io
import logging
import os
import re
import stat
import threading
import xml.parsers.expat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import xacro
import xacro.substitution_args as _subst

from rrbot_workshop.description import xacro_cache
from rrbot_workshop.description.packages import descriptions_root
from rrbot_workshop.exceptions import DescriptionError

__all__ = ["descriptions_root", "process_xacro", "resolve_package_uri", "available_packages", "find_package"]

logger = logging.getLogger(__name__)

_LOCK = threading.RLock()
#: What the expansion running now reads (set inside :func:`_xacro_sandbox`, under :data:`_LOCK`).
_RECORDER: xacro_cache.Recorder | None = None


def available_packages() -> list[str]:
    """Names of the packages on the package path (by default the folders of :func:`descriptions_root`), sorted."""
    from rrbot_workshop.description.packages import package_index

    return package_index().names()


def find_package(package: str) -> Path:
    """The share folder of a package, the stand-in for ROS' ``get_package_share_directory``.

    Args:
        package: Package name, e.g. ``"rrbot"``.

    Returns:
        ``descriptions_root() / package`` for the course's descriptions, the installed ``share/<pkg>`` folder, or
        for a source tree the folder that looks like its installed form
        (:func:`~rrbot_workshop.description.packages.share_directory`).

    Raises:
        DescriptionError: If there is no such package; the message lists the packages that exist and the path
            searched.
    """
    from rrbot_workshop.description.packages import share_directory

    try:
        return share_directory(package)
    except DescriptionError as exc:
        raise DescriptionError(str(exc), element="$(find)", attribute=package) from None


def resolve_package_uri(uri: str, base: str | Path | None = None) -> Path:
    """Turn a mesh or resource URI into a file path.

    Args:
        uri: ``package://<pkg>/<path>``, ``file://<abs path>``, or a plain path.
        base: Folder for relative plain paths (default: the current directory).

    Returns:
        The file path (not checked for existence, so viewers can report missing meshes themselves).

    Raises:
        DescriptionError: If a ``package://`` URI names an unknown package or has no package name.
    """
    if uri.startswith("package://"):
        from rrbot_workshop.description.packages import resolve_uri

        return resolve_uri(uri, must_exist=False)
    if uri.startswith("file://"):
        return Path(uri[len("file://"):])
    path = Path(uri)
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    return path


def _mapping_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, Path):
        return str(value)
    return str(value)


def _open_regular(file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
    """``open`` for xacro: a file read (the description, an include, a YAML file) must be a regular file, so a FIFO
    or a device named by a description never blocks or floods the expansion."""
    if isinstance(file, int) or any(c in mode for c in "wax+"):
        return open(file, mode, *args, **kwargs)  # noqa: SIM115 - xacro closes what it opens
    fd = os.open(file, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file (a FIFO, a device or a folder)", str(file))
        os.set_blocking(fd, True)
        if _RECORDER is None:
            return open(fd, mode, *args, **kwargs)  # noqa: SIM115 - xacro closes what it opens
        with open(fd, "rb", closefd=False) as raw:
            data = raw.read()
        os.close(fd)
    except BaseException:
        os.close(fd)
        raise
    _RECORDER.read(str(file), data)  # the bytes xacro gets are the bytes whose digest is kept
    if "b" in mode:
        return io.BytesIO(data)
    return io.TextIOWrapper(io.BytesIO(data), encoding=kwargs.get("encoding"), errors=kwargs.get("errors"),
                            newline=kwargs.get("newline"))


def _share_directory(pkg: str) -> str:
    from rrbot_workshop.description.packages import share_directory

    return str(share_directory(pkg))


#: The largest literal exponent a ``${...}`` expression may raise to: ``10**10**10`` would compute for ever.
MAX_XACRO_EXPONENT = 10_000


#: Code of the ``${...}`` expressions compiled so far in this process, by (source, filename, mode): a description
#: expanded with other arguments, or a grader's next robot, evaluates the same expressions again.
_COMPILED: dict[tuple[str, str, str], Any] = {}
#: Expressions kept at most (a learner's generated descriptions cannot grow the process without end).
MAX_COMPILED = 4096


def _compile_bounded(source: Any, filename: str, mode: str, *args: Any, **kwargs: Any) -> Any:
    """Python's ``compile`` for xacro's ``${...}`` expressions, refusing a power whose exponent is a literal above
    :data:`MAX_XACRO_EXPONENT` or itself a power (a tower such as ``10**10**10``), which would never finish.

    The code of an expression compiled before is given again (code objects never change): parsing, checking and
    compiling them was a seventh of an expansion's time.

    Raises:
        xacro.XacroException: Naming the expression (reported as a DescriptionError with the file).
    """
    key = (source, filename, mode) if isinstance(source, str) and not args and not kwargs else None
    if key is not None:
        code = _COMPILED.get(key)
        if code is not None:
            return code
    code = _checked_compile(source, filename, mode, *args, **kwargs)
    if key is not None:
        if len(_COMPILED) >= MAX_COMPILED:
            _COMPILED.clear()
        _COMPILED[key] = code
    return code


def _checked_compile(source: Any, filename: str, mode: str, *args: Any, **kwargs: Any) -> Any:
    if isinstance(source, str):
        try:
            tree = ast.parse(source.strip(), mode="eval")
        except SyntaxError:
            tree = None
        for node in ast.walk(tree) if tree is not None else ():
            if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
                exponent = node.right
                if isinstance(exponent, ast.UnaryOp):
                    exponent = exponent.operand
                too_big = isinstance(exponent, ast.Constant) and isinstance(exponent.value, int | float) \
                    and abs(exponent.value) > MAX_XACRO_EXPONENT
                if too_big or (isinstance(exponent, ast.BinOp) and isinstance(exponent.op, ast.Pow)):
                    raise xacro.XacroException(f"expression '{source.strip()[:80]}' raises to a power beyond "
                                               f"{MAX_XACRO_EXPONENT} and would not finish")
    return compile(source, filename, mode, *args, **kwargs)


#: Tokens of the texts xacro's ``eval_text`` lexed in this process (attribute values and text: the same few hundred
#: again at every expansion): text -> (its tokens, the rest no token matched or None).
_TOKENS: dict[str, tuple[tuple[tuple[int, str], ...], str | None]] = {}


def _tokens(text: str) -> tuple[tuple[tuple[int, str], ...], str | None]:
    """``text`` cut as xacro's lexer cuts it: the first of its patterns that matches, repeatedly."""
    kept = _TOKENS.get(text)
    if kept is not None:
        return kept
    patterns = xacro.LEXER.res
    found: list[tuple[int, str]] = []
    rest: str | None = None
    left = text
    while left:
        for index, pattern in enumerate(patterns):
            match = pattern.match(left)
            if match:
                found.append((index, match.group(0)))
                left = left[match.end():]
                break
        else:
            rest = left
            break
    if len(_TOKENS) >= MAX_COMPILED:
        _TOKENS.clear()
    kept = _TOKENS[text] = (tuple(found), rest)
    return kept


class _KeptLexer(xacro.QuickLexer):  # type: ignore[misc]
    """xacro's lexer for ``eval_text`` with the tokens of each text kept (see :data:`_TOKENS`): the same tokens in the
    same order, and the same error at the same step for a text with an invalid part."""

    def lex(self, str: str) -> None:  # noqa: A002 - xacro's own parameter name
        self._found, self._rest = _tokens(str)
        self._at = -1
        self.top = None
        self.next()

    def next(self) -> Any:
        result = self.top
        self._at += 1
        if self._at < len(self._found):
            self.top = self._found[self._at]  # type: ignore[assignment]
            return result
        self.top = None
        if self._rest is not None:
            raise xacro.XacroException("invalid expression: " + self._rest)
        return result


@contextmanager
def _xacro_sandbox(recorder: xacro_cache.Recorder | None = None) -> Iterator[None]:
    """Redirect ``$(find)`` to :func:`find_package` and restore every xacro global afterwards; with a ``recorder``,
    note everything the expansion reads (files, packages, wildcard matches, environment variables)."""
    global _RECORDER

    found: dict[str, str] = {}  # one share folder per package for the whole run, as a sourced workspace gives

    def _eval_find(pkg: str) -> str:
        folder = found[pkg] = found.get(pkg) or _share_directory(pkg)
        if recorder is not None:
            recorder.finds[pkg] = folder
        return folder

    def _eval_env(name: str) -> str:
        if recorder is not None:
            recorder.env[name] = os.environ.get(name)
        return saved_env(name)

    def _eval_optenv(name: str, default: str = "") -> str:
        if recorder is not None:
            recorder.env[name] = os.environ.get(name)
        return saved_optenv(name, default)

    saved_find = _subst._eval_find
    saved_env, saved_optenv = _subst._eval_env, _subst._eval_optenv
    saved_dict = {key: _subst._eval_dict.get(key) for key in ("find", "env", "optenv")}
    saved_verbosity = xacro.verbosity
    saved_includes = list(xacro.all_includes)
    saved_filestack = xacro.filestack
    saved_macrostack = xacro.macrostack
    with _LOCK:
        _subst._eval_find = _eval_find  # type: ignore[assignment]
        _subst._eval_env, _subst._eval_optenv = _eval_env, _eval_optenv  # type: ignore[assignment]
        _subst._eval_dict.update(find=_eval_find, env=_eval_env, optenv=_eval_optenv)
        saved_open = vars(xacro).get("open")
        saved_glob = xacro.glob
        xacro.open = _open_regular  # type: ignore[attr-defined]  # shadows the builtin in xacro's module only
        xacro.compile = _compile_bounded  # type: ignore[attr-defined]  # likewise: ${...} expressions
        saved_lexer = xacro.QuickLexer
        xacro.QuickLexer = _KeptLexer  # eval_text's lexer (the only one made while expanding)
        if recorder is not None:
            xacro.glob = recorder  # type: ignore[assignment]  # xacro calls glob.glob for wildcard includes
        _RECORDER = recorder
        try:
            yield
        finally:
            _RECORDER = None
            xacro.glob = saved_glob
            xacro.QuickLexer = saved_lexer
            vars(xacro).pop("compile", None)
            if saved_open is None:
                vars(xacro).pop("open", None)
            else:
                xacro.open = saved_open  # type: ignore[attr-defined]
            _subst._eval_find = saved_find  # type: ignore[assignment]
            _subst._eval_env, _subst._eval_optenv = saved_env, saved_optenv  # type: ignore[assignment]
            _subst._eval_dict.update(saved_dict)
            xacro.verbosity = saved_verbosity
            xacro.all_includes[:] = saved_includes
            xacro.filestack = saved_filestack
            xacro.macrostack = saved_macrostack
            xacro.substitution_args_context["arg"] = {}


def _location() -> str:
    """Where xacro was when it failed: the innermost file of its include stack, if known."""
    stack = [f for f in (xacro.filestack or []) if f]
    macros = [m.body.getAttribute("name") for m in (xacro.macrostack or [])]
    parts = []
    if stack:
        parts.append(f"in file {stack[-1]}")
    if macros:
        parts.append("in macro " + " > ".join(macros))
    return f" ({', '.join(parts)})" if parts else ""


def _find_in_chain(err: BaseException, kind: type[BaseException]) -> BaseException | None:
    """The first exception of type ``kind`` in ``err``'s chain, however xacro wrapped it."""
    seen: set[int] = set()
    current: BaseException | None = err
    while current is not None and id(current) not in seen:
        seen.add(id(current))
        if isinstance(current, kind):
            return current
        nxt = getattr(current, "exc", None)
        current = nxt if isinstance(nxt, BaseException) else (current.__cause__ or current.__context__)
    return None


_TAG = re.compile(r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<!.*?>|<(/?)([A-Za-z_][\w:.-]*)((?:[^>\"']|\"[^\"]*\"|'[^']*')*?)(/?)>", re.S)


def unclosed_element(path: Path) -> str:
    """The element left open in an XML file, as a learner would say it: ``<visual> opened at line 12 is not closed
    (</link> at line 20 closes <link> from line 8)``; ``""`` if the tags balance or the file cannot be read."""
    try:
        text = path.read_text()
    except OSError:
        return ""
    stack: list[tuple[str, int, str]] = []
    for match in _TAG.finditer(text):
        closing, name, attrs, selfclosing = match.group(1), match.group(2), match.group(3), match.group(4)
        if name is None or selfclosing:
            continue
        line = text.count("\n", 0, match.start()) + 1
        if not closing:
            found = re.search(r"name\s*=\s*[\"']([^\"']*)", attrs or "")
            stack.append((name, line, f" name='{found.group(1)}'" if found else ""))
            continue
        if stack and stack[-1][0] == name:
            stack.pop()
            continue
        if stack:
            open_name, open_line, open_label = stack[-1]
            return (f"<{open_name}{open_label}> opened at line {open_line} is not closed "
                    f"(</{name}> at line {line} comes first)")
        return f"</{name}> at line {line} closes an element that is not open"
    if stack:
        open_name, open_line, open_label = stack[-1]
        return f"<{open_name}{open_label}> opened at line {open_line} is never closed"
    return ""


def _as_description_error(err: Exception, file: Path) -> DescriptionError:
    where = _location()
    inner = _find_in_chain(err, DescriptionError)
    if isinstance(inner, DescriptionError):
        text = str(inner)
        return DescriptionError(f"{text}{where}", source=str(file), element=inner.element, attribute=inner.attribute)
    missing = _find_in_chain(err, FileNotFoundError)
    if isinstance(missing, FileNotFoundError) and missing.filename:
        from rrbot_workshop.description.packages import explain_missing

        explained = explain_missing(missing.filename)
        if explained is not None:  # a file missing from a source tree's install view: say where it was looked for
            return DescriptionError(f"{explained}{where}", source=str(file), element=explained.element,
                                    attribute=explained.attribute)
    expat = _find_in_chain(err, xml.parsers.expat.ExpatError)
    if expat is not None:
        stack = [f for f in (xacro.filestack or []) if f]
        bad_file = Path(stack[-1]) if stack else file
        line = getattr(expat, "lineno", 0)
        column = getattr(expat, "offset", 0)
        open_element = unclosed_element(bad_file)
        detail = f"; {open_element}" if open_element else ""
        return DescriptionError(
            f"malformed XML at line {line}, column {column + 1}: "
            f"{xml.parsers.expat.ErrorString(expat.code) if hasattr(expat, 'code') else expat}{detail}",
            source=str(bad_file),
        )
    arg_error = _find_in_chain(err, _subst.ArgException)
    if arg_error is not None:
        name = str(arg_error).strip("'\"")
        return DescriptionError(
            f"undefined xacro argument '{name}' (pass it as a mapping or declare <xacro:arg name='{name}'/>){where}",
            source=str(file),
        )
    text = " ".join(str(err).split()) or repr(err)
    return DescriptionError(f"xacro failed: {text}{where}", source=str(file))


def process_xacro(path: str | Path, **mappings: Any) -> str:
    """Expand a xacro file into URDF text, as ``xacro file.xacro key:=value`` does.

    Args:
        path: The ``.xacro`` (or ``.urdf``) file.
        **mappings: Xacro arguments (``prefix="r1_"``, ``use_mock_hardware=True``). Values that are not strings
            are converted: booleans to ``"true"``/``"false"``, everything else with ``str()``.

    Returns:
        The URDF as an XML string.

    Raises:
        DescriptionError: If the file does not exist, xacro fails (bad XML, undefined property or argument,
            failing ``xacro:fatal``), or ``$(find pkg)`` names an unknown package. The message names the file.
    """
    if not isinstance(path, str | os.PathLike) or not str(path).strip() or "\x00" in str(path):
        raise DescriptionError(f"the xacro file must be given as a path, got {path!r}", source=repr(path)[:80])
    file = Path(path).expanduser()
    if not file.is_file():
        hint = "" if file.parent.is_dir() else f" (folder {file.parent} does not exist either)"
        raise DescriptionError(f"xacro file not found{hint}", source=str(file))
    file = file.resolve()
    str_mappings = {str(k): _mapping_value(v) for k, v in mappings.items()}
    with _LOCK:
        kept = xacro_cache.EXPANSIONS.get(file, str_mappings, _share_directory)
        if kept is not None:
            logger.debug("%s with %s: unchanged since its last expansion", file, str_mappings)
            return kept
        recorder = xacro_cache.Recorder()
        with _xacro_sandbox(recorder):
            try:
                # a copy: xacro adds the defaults of the arguments not given to the mappings it is handed, and the
                # expansion is kept under the arguments the caller gave
                doc = xacro.process_file(str(file), mappings=dict(str_mappings), verbosity=0)
            except Exception as err:  # noqa: BLE001 - xacro raises many types; all become DescriptionError
                raise _as_description_error(err, file) from err
            text = doc.toprettyxml(indent="  ")
        xacro_cache.EXPANSIONS.put(file, str_mappings, text, recorder)
    logger.debug("processed %s with %s", file, str_mappings)
    return text
