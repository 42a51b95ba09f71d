"""The per-process cache of xacro expansions: the same file with the same arguments is expanded once, and again as
soon as anything it read changed (an included file, a YAML file, a wildcard's matches, a package's folder, an
environment variable)."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest
import xacro

from rrbot_workshop.description import process_xacro, xacro_cache
from rrbot_workshop.description.packages import DESCRIPTIONS_ENV, use_package_path
from rrbot_workshop.exceptions import DescriptionError

_HEAD = '<?xml version="1.0"?>\n<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


@pytest.fixture
def alpha(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """The ``urdf`` folder of package ``alpha`` in a descriptions root of its own; the cache starts empty."""
    (tmp_path / "alpha" / "urdf").mkdir(parents=True)
    monkeypatch.setenv(DESCRIPTIONS_ENV, str(tmp_path))
    monkeypatch.delenv(xacro_cache.SHARED_ENV, raising=False)  # this process's cache alone (a session may share one)
    xacro_cache.clear()
    yield tmp_path / "alpha" / "urdf"
    xacro_cache.clear()


def _robot(body: str) -> str:
    return _HEAD + body + "\n</robot>\n"


def _counts() -> tuple[int, int]:
    return xacro_cache.EXPANSIONS.hits, xacro_cache.EXPANSIONS.misses


def test_the_same_file_and_arguments_are_expanded_once(alpha: Path) -> None:
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:arg name="p" default=""/><link name="$(arg p)l"/>'))
    first = process_xacro(path, p="a_")
    assert process_xacro(path, p="a_") == first and _counts() == (1, 1)
    assert '<link name="b_l"/>' in process_xacro(path, p="b_"), "other arguments: another expansion"
    assert _counts() == (1, 2)


def test_arguments_left_to_their_defaults_are_expanded_once_too(alpha: Path) -> None:
    """xacro fills the defaults into the mappings it is given; the expansion is still kept under the caller's."""
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:arg name="p" default="d_"/><xacro:arg name="q" default="x"/>'
                           '<link name="$(arg p)$(arg q)"/>'))
    first = process_xacro(path, q="y")
    assert '<link name="d_y"/>' in first
    assert process_xacro(path, q="y") == first and process_xacro(path) != first
    assert _counts() == (1, 2)


def test_an_edited_include_is_expanded_again(alpha: Path) -> None:
    (alpha / "part.xacro").write_text(_robot('<link name="one"/>'))
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:include filename="part.xacro"/>'))
    assert '<link name="one"/>' in process_xacro(path)
    (alpha / "part.xacro").write_text(_robot('<link name="two"/>'))
    urdf = process_xacro(path)
    assert '<link name="two"/>' in urdf and '<link name="one"/>' not in urdf


def test_an_edited_yaml_file_is_read_again(alpha: Path) -> None:
    (alpha / "values.yaml").write_text("length: 1.5\n")
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:property name="v" value="${xacro.load_yaml(\'values.yaml\')}"/>'
                           '<link name="l${v[\'length\']}"/>'))
    assert '<link name="l1.5"/>' in process_xacro(path)
    (alpha / "values.yaml").write_text("length: 2.5\n")
    assert '<link name="l2.5"/>' in process_xacro(path)


def test_a_file_added_to_a_wildcard_include_is_included(alpha: Path) -> None:
    (alpha / "parts").mkdir()
    (alpha / "parts" / "a.xacro").write_text(_robot('<link name="a"/>'))
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:include filename="parts/*.xacro"/>'))
    assert '<link name="b"/>' not in process_xacro(path)
    (alpha / "parts" / "b.xacro").write_text(_robot('<link name="b"/>'))
    assert '<link name="b"/>' in process_xacro(path)


def test_a_changed_environment_variable_is_read_again(alpha: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = alpha / "r.xacro"
    path.write_text(_robot('<link name="$(optenv RRBOT_TEST_LINK none)"/>'))
    assert '<link name="none"/>' in process_xacro(path)
    monkeypatch.setenv("RRBOT_TEST_LINK", "set")
    assert '<link name="set"/>' in process_xacro(path)


def test_another_package_path_finds_another_package(alpha: Path, tmp_path: Path) -> None:
    """``$(find beta)`` is looked up again: a package path given later may hold another beta."""
    for where, name in ((tmp_path, "root"), (tmp_path / "elsewhere", "elsewhere")):
        (where / "beta" / "urdf").mkdir(parents=True)
        (where / "beta" / "package.xml").write_text("<package format='3'><name>beta</name></package>")
        (where / "beta" / "urdf" / "m.xacro").write_text(_robot(f'<link name="{name}"/>'))
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:include filename="$(find beta)/urdf/m.xacro"/>'))
    assert '<link name="root"/>' in process_xacro(path)
    with use_package_path([tmp_path / "elsewhere"]):
        assert '<link name="elsewhere"/>' in process_xacro(path)
    assert '<link name="root"/>' in process_xacro(path)


def test_a_failed_expansion_is_not_kept(alpha: Path) -> None:
    path = alpha / "r.xacro"
    path.write_text(_robot('<link name="${nope}"/>'))
    for _ in range(2):
        with pytest.raises(DescriptionError, match="nope"):
            process_xacro(path)
    assert len(xacro_cache.EXPANSIONS) == 0


def test_xacros_own_lookups_are_restored_after_an_expansion(alpha: Path) -> None:
    """The recording hooks (open, glob, $(env), $(optenv)) live only while an expansion runs."""
    before = (vars(xacro).get("open"), xacro.glob, xacro.substitution_args._eval_env)
    path = alpha / "r.xacro"
    path.write_text(_robot('<link name="a"/>'))
    process_xacro(path)
    assert (vars(xacro).get("open"), xacro.glob, xacro.substitution_args._eval_env) == before


def test_the_cache_keeps_at_most_its_size(alpha: Path) -> None:
    cache = xacro_cache.ExpansionCache(size=2)
    recorder = xacro_cache.Recorder()
    for name in ("a", "b", "c"):
        cache.put(alpha / name, {}, name, recorder)
    assert len(cache) == 2 and cache.get(alpha / "a", {}, str) is None and cache.get(alpha / "c", {}, str) == "c"


def test_an_expression_is_compiled_once_and_a_refused_one_every_time(alpha: Path) -> None:
    """Expanding with other arguments evaluates the same ``${...}`` again: its code is kept; a power beyond the
    bound is refused on every expansion, never kept."""
    from rrbot_workshop.description import xacro as xacro_module

    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:arg name="p" default=""/><link name="$(arg p)${2 * 21}"/>'))
    assert '<link name="a_42"/>' in process_xacro(path, p="a_")
    kept = xacro_module._COMPILED[("2 * 21", "<expression>", "eval")]
    assert '<link name="b_42"/>' in process_xacro(path, p="b_")
    assert xacro_module._COMPILED[("2 * 21", "<expression>", "eval")] is kept
    tower = alpha / "tower.xacro"
    tower.write_text(_robot('<xacro:arg name="p" default=""/><link name="$(arg p)${10**10**10}"/>'))
    for prefix in ("a_", "b_"):
        with pytest.raises(DescriptionError, match="beyond"):
            process_xacro(tower, p=prefix)
    assert not any("10**10**10" in key[0] for key in xacro_module._COMPILED)


def _steps(lexer_class: type, text: str) -> list[object]:
    """What ``eval_text`` sees of a lexer on ``text``: each token in turn, then the end or the error's message."""
    seen: list[object] = []
    try:
        lexer = lexer_class(xacro.LEXER)
        lexer.lex(text)
        while lexer.peek():
            seen.append(lexer.next())
        seen.append("end")
    except xacro.XacroException as exc:
        seen.append(f"error: {exc}")
    return seen


@pytest.mark.parametrize("text", ["", "plain", "${a * 2}", "$(arg p)link_${i}", "$${escaped} $$(x) $", "a$b${c}$(d)e",
                                  "${unclosed", "$(unclosed", "x ${1} $(", "${a}${b}${c}"])
def test_a_kept_lexer_cuts_a_text_as_xacros_own_does_twice(text: str) -> None:
    """The tokens of a text lexed before are given again: the same tokens, then the same end or the same error."""
    from rrbot_workshop.description import xacro as xacro_module

    own = _steps(xacro.QuickLexer, text)
    assert _steps(xacro_module._KeptLexer, text) == own
    assert _steps(xacro_module._KeptLexer, text) == own, "from the kept tokens"


def test_a_file_expanded_with_its_argument_defaults_is_expanded_once(alpha: Path) -> None:
    """xacro fills the arguments it is given with each ``<xacro:arg>``'s default: the cache's key is what the caller
    gave, so the next call with the same arguments finds it."""
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:arg name="p" default="d_"/><xacro:arg name="q" default="x"/>'
                           '<link name="$(arg p)$(arg q)"/>'))
    first = process_xacro(path)
    assert '<link name="d_x"/>' in first
    assert process_xacro(path) == first and _counts() == (1, 1)
    assert '<link name="e_x"/>' in process_xacro(path, p="e_")
    assert '<link name="e_x"/>' in process_xacro(path, p="e_") and _counts() == (2, 2)


@pytest.fixture
def shared(alpha: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A folder named by ``$RRBOT_WORKSHOP_XACRO_CACHE``, where processes share their expansions."""
    folder = tmp_path / "shared"
    monkeypatch.setenv(xacro_cache.SHARED_ENV, str(folder))
    return folder


def _another_process() -> None:
    """What a process that has expanded nothing yet sees: this process's kept expansions are forgotten."""
    xacro_cache.clear()


def test_an_expansion_is_shared_with_a_process_that_has_not_made_it(alpha: Path, shared: Path) -> None:
    (alpha / "part.xacro").write_text(_robot('<xacro:arg name="p" default=""/><link name="$(arg p)one"/>'))
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:arg name="p" default=""/><xacro:include filename="part.xacro"/>'))
    first = process_xacro(path, p="a_")
    assert len(list(shared.glob("*.json"))) == 1
    _another_process()
    assert process_xacro(path, p="a_") == first
    assert (xacro_cache.EXPANSIONS.shared_hits, xacro_cache.EXPANSIONS.misses) == (1, 0)
    assert '<link name="b_one"/>' in process_xacro(path, p="b_"), "other arguments: another entry"
    assert xacro_cache.EXPANSIONS.misses == 1 and len(list(shared.glob("*.json"))) == 2


def test_a_shared_expansion_is_made_again_once_an_included_file_changed(alpha: Path, shared: Path) -> None:
    """The entry another process left is checked as a kept one: an include edited since is read again, and the
    folder's entry is replaced by the new expansion."""
    (alpha / "part.xacro").write_text(_robot('<link name="one"/>'))
    path = alpha / "r.xacro"
    path.write_text(_robot('<xacro:include filename="part.xacro"/>'))
    assert '<link name="one"/>' in process_xacro(path)
    (alpha / "part.xacro").write_text(_robot('<link name="two"/>'))
    _another_process()
    urdf = process_xacro(path)
    assert '<link name="two"/>' in urdf and '<link name="one"/>' not in urdf
    assert (xacro_cache.EXPANSIONS.shared_hits, xacro_cache.EXPANSIONS.misses) == (0, 1)
    _another_process()
    assert process_xacro(path) == urdf and xacro_cache.EXPANSIONS.shared_hits == 1


def test_a_shared_expansion_is_made_again_when_a_variable_it_read_changed(alpha: Path, shared: Path,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RRBOT_TEST_LINK", "first")
    path = alpha / "r.xacro"
    path.write_text(_robot('<link name="$(optenv RRBOT_TEST_LINK none)"/>'))
    assert '<link name="first"/>' in process_xacro(path)
    monkeypatch.setenv("RRBOT_TEST_LINK", "second")
    _another_process()
    assert '<link name="second"/>' in process_xacro(path) and xacro_cache.EXPANSIONS.shared_hits == 0


@pytest.mark.parametrize("damage", ["", "{not json", '{"key": ["elsewhere", []], "text": "<robot/>", "files": {}, '
                                    '"finds": {}, "globs": {}, "env": {}}', '{"key": 7}'])
def test_a_damaged_or_foreign_shared_entry_is_ignored(alpha: Path, shared: Path, damage: str) -> None:
    """An entry cut short, not JSON, or of another file is not used: the file is expanded and the entry rewritten."""
    path = alpha / "r.xacro"
    path.write_text(_robot('<link name="a"/>'))
    urdf = process_xacro(path)
    (entry,) = shared.glob("*.json")
    entry.write_text(damage)
    _another_process()
    assert process_xacro(path) == urdf and (xacro_cache.EXPANSIONS.shared_hits, xacro_cache.EXPANSIONS.misses) == (0, 1)
    assert json.loads(entry.read_text())["text"] == urdf


def _expand_in_a_new_process(path: str) -> tuple[str, int]:
    return process_xacro(path), xacro_cache.EXPANSIONS.shared_hits


def test_a_new_process_finds_the_expansion_of_another(alpha: Path, shared: Path) -> None:
    """A new Python process (with this one's environment, as a grading or a notebook's kernel gets it) reads the
    expansion this one wrote, without expanding."""
    import multiprocessing

    path = alpha / "r.xacro"
    path.write_text(_robot('<link name="a"/>'))
    urdf = process_xacro(path)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.apply(_expand_in_a_new_process, (str(path),)) == (urdf, 1)
