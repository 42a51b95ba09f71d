"""Short tracebacks of library errors in notebooks (%load_ext rrbot_workshop), with %tb for the full one."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from IPython.core.interactiveshell import InteractiveShell

import rrbot_workshop as rw
from rrbot_workshop.course.tracebacks import is_learner_frame, short_traceback_lines

BROKEN_XACRO = textwrap.dedent(
    """\
    <?xml version="1.0"?>
    <robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">
      <link name="${undefined_property * 2}"/>
    </robot>
    """
)


@pytest.fixture(scope="module")
def shell():
    ip = InteractiveShell.instance()
    ip.run_line_magic("load_ext", "rrbot_workshop")
    yield ip
    ip.set_custom_exc((), None)


def test_library_error_in_a_cell_shows_the_clear_line_first_and_the_cells_frame(shell, tmp_path: Path, capsys):
    xacro = tmp_path / "broken.urdf.xacro"
    xacro.write_text(BROKEN_XACRO, encoding="utf-8")
    result = shell.run_cell(f"import rrbot_workshop as rw\nurdf = rw.description.process_xacro({str(xacro)!r})\n")
    out = capsys.readouterr().out
    assert isinstance(result.error_in_exec, rw.DescriptionError)
    lines = [line for line in out.splitlines() if line.strip()]
    assert lines[0].startswith("DescriptionError: ") and "undefined_property" in lines[0]
    assert "line 2: urdf = rw.description.process_xacro(" in lines[1]
    assert "run %tb for the full traceback" in lines[-1]
    assert "rrbot_workshop/description" not in out  # no library frame


def test_percent_tb_then_shows_the_full_traceback(shell, capsys):
    shell.run_cell("import rrbot_workshop as rw\nrw.params.load_controllers_yaml('/no/such/file.yaml')\n")
    short = capsys.readouterr().out
    shell.run_cell("%tb")
    full = capsys.readouterr().out
    assert "rrbot_workshop" in full and "params" in full
    assert len(full.splitlines()) > len(short.splitlines())


def test_other_exceptions_keep_ipythons_traceback(shell, capsys):
    shell.run_cell("def f():\n    raise ValueError('plain')\nf()\n")
    out = capsys.readouterr().out
    assert "ValueError" in out and "run %tb" not in out


def test_learner_frames_are_cells_and_files_outside_the_library():
    assert is_learner_frame("/tmp/ipykernel_1/123.py")
    assert is_learner_frame("/home/me/course/exercises/task02/rrbot_bringup/bringup.py")
    assert not is_learner_frame(rw.__file__)
    assert not is_learner_frame(pytest.__file__)
    assert not is_learner_frame("<frozen importlib._bootstrap>")


def test_short_lines_of_an_error_raised_in_a_learners_file(tmp_path: Path):
    learner = tmp_path / "answers.py"
    learner.write_text("import rrbot_workshop as rw\n\ndef go():\n    rw.params.load_controllers_yaml('/nope.yaml')\n")
    code = compile(learner.read_text(), str(learner), "exec")
    namespace: dict = {}
    exec(code, namespace)
    with pytest.raises(rw.RRBotWorkshopError) as info:
        namespace["go"]()
    lines = short_traceback_lines(info.value, info.value.__traceback__)
    assert lines[0] == f"{type(info.value).__name__}: {info.value}"
    assert "  answers.py, line 4: rw.params.load_controllers_yaml('/nope.yaml')" in lines
    assert not any("params" in line and "rrbot_workshop" in line for line in lines[1:-1])


BROKEN_DRIVER = textwrap.dedent(
    """\
    from rrbot_workshop.hardware import SystemInterface


    class BrokenDriver(SystemInterface):
        def on_configure(self, previous_state):
            return self.open_device()
    """
)


def test_a_learner_exception_the_library_caught_in_the_cell_is_shown_before_the_library_error(
    shell, tmp_path: Path, capsys, monkeypatch
):
    """The driver's on_configure raises; the library logs it and refuses the switch: the cell shows the learner's
    file, line, function and exception first, then the switch error; the next cell forgets it."""
    (tmp_path / "broken_driver_tb.py").write_text(BROKEN_DRIVER, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    cell = textwrap.dedent(
        """\
        import rrbot_workshop as rw, broken_driver_tb
        from rrbot_workshop.middleware import plugins
        plugins.register("hardware", "test_tracebacks/BrokenDriver", broken_driver_tb.BrokenDriver)
        root = rw.description.descriptions_root()
        urdf = rw.description.process_xacro(root / "rrbot/urdf/rrbot.urdf.xacro", use_mock_hardware=False)
        urdf = urdf.replace("controlko_hardware_interface/RRBotHardwareInterface", "test_tracebacks/BrokenDriver")
        system = rw.bringup(urdf, root / "rrbot/config/rrbot_controllers.yaml", spawn=["forward_position_controller"])
        """
    )
    try:
        result = shell.run_cell(cell)
        out = capsys.readouterr().out
        assert isinstance(result.error_in_exec, rw.SwitchError)
        lines = [line for line in out.splitlines() if line.strip()]
        assert lines[0].startswith("Your code raised first")
        assert lines[1] == "  broken_driver_tb.py, line 6, in on_configure: return self.open_device()"
        assert lines[2] == "    AttributeError: 'BrokenDriver' object has no attribute 'open_device'"
        assert lines[3] == "Then:" and lines[4].startswith("SwitchError: switch rejected")
        result = shell.run_cell("rw.description.process_xacro('no_such_file.urdf.xacro')")
        assert isinstance(result.error_in_exec, rw.DescriptionError)
        assert "Your code raised first" not in capsys.readouterr().out
    finally:
        from rrbot_workshop.middleware import plugins

        plugins.unregister("hardware", "test_tracebacks/BrokenDriver")
