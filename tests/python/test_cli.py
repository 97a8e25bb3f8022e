# SPDX-License-Identifier: GPL-2.0-or-later
"""The sediment command line."""
import argparse
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sediment
from sediment import cli
from sediment.cli import types
from sediment.plausible import RANGES
from sediment.studies.single_sphere import case_a_sweep

REPO = Path(__file__).resolve().parents[2]


def test_terminal_prints_velocity_tau_and_t99(capsys):
    assert cli.main(["terminal", "--diameter", "1e-4", "--particle-density", "2700", "--fluid-density", "1000",
                     "--viscosity", "1e-3"]) == 0
    out = capsys.readouterr().out
    assert "terminal velocity: 0.009265 m/s (moving)" in out
    assert "tau = m / F'(0): 0.0015 s" in out


def test_terminal_bingham_at_rest(capsys):
    assert cli.main(["terminal", "--law", "zhang-li", "--diameter", "0.02", "--particle-density", "1500",
                     "--fluid-density", "1280", "--viscosity", "0.0131", "--yield-stress", "30.5"]) == 0
    assert "terminal velocity: 0 m/s (at_rest)" in capsys.readouterr().out


def test_bad_arguments_are_refused_without_traceback():
    for args in (["terminal", "--diameter", "-1", "--particle-density", "2700"],
                 ["terminal", "--law", "newton", "--diameter", "1e-4", "--particle-density", "2700"]):
        proc = subprocess.run([str(REPO / "bin" / "sediment"), *args], capture_output=True, text=True)
        assert proc.returncode == 2
        assert "Traceback" not in proc.stderr and "error:" in proc.stderr


def test_help_lists_commands():
    proc = subprocess.run([str(REPO / "bin" / "sediment"), "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "terminal" in proc.stdout and "case-a" in proc.stdout


@pytest.mark.parametrize("integrator, bound", [("implicit", 1e-12), ("explicit", 0.2)])
def test_case_a_runs_through_the_driver(integrator, bound, tmp_path):
    run, = case_a_sweep((1e-3,), (integrator,), t_end=0.01, work_dir=tmp_path, progress=False).runs
    assert run.error < bound
    assert len(run.observations["velocity"].x) == 11


def test_readout_preview_writes_tables_figure_and_errors(tmp_path, capsys):
    psd = REPO / "examples" / "granulometry" / "psd" / "sample5.csv"
    assert cli.main(["readout", "--psd", str(psd), "--stokes-preview", "--out", str(tmp_path)]) == 0
    for name in ("hydrometer.csv", "buoyancy.csv", "pipette.csv", "errors.csv", "granulometry.png", "granulometry.pdf"):
        assert (tmp_path / name).stat().st_size > 0
    rows = (tmp_path / "errors.csv").read_text().splitlines()[1:]
    assert len(rows) == 9 and all(float(r.split(",")[4]) < 2.0 for r in rows if r.split(",")[3] != "0")


def test_readout_bad_inputs_are_clear(tmp_path, capsys):
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    assert cli.main(["readout", "--psd", str(empty), "--stokes-preview", "--out", str(tmp_path)]) == 2
    assert "empty PSD file" in capsys.readouterr().err
    foreign = tmp_path / "other.h5"
    import h5py
    with h5py.File(foreign, "w") as f:
        f.attrs["schema"] = "something-else"
    assert cli.main(["readout", str(foreign), "--out", str(tmp_path)]) == 2
    assert "not a SEDIMENT layer file" in capsys.readouterr().err


def test_readout_measured_hydrometer_option(tmp_path):
    """The nominal 152H given as a measured instrument (--hydrometer) reads the same."""
    from sediment.lab.readout import Hydrometer
    psd = REPO / "examples" / "granulometry" / "psd" / "sample5.csv"
    h = Hydrometer.astm_152h()
    measured = [h.bulb_length, h.bulb_volume, float(np.sqrt(4 * h.stem_area / np.pi)), h.mass, h.scale_zero,
                h.scale_zero - 50 * h.scale_step]
    base = ["readout", "--psd", str(psd), "--stokes-preview", "--instrument", "hydrometer"]
    assert cli.main(base + ["--out", str(tmp_path / "a")]) == 0
    assert cli.main(base + ["--out", str(tmp_path / "b"), "--hydrometer", *map(repr, measured)]) == 0
    a = np.genfromtxt(tmp_path / "a" / "hydrometer.csv", delimiter=",", skip_header=1)
    b = np.genfromtxt(tmp_path / "b" / "hydrometer.csv", delimiter=",", skip_header=1)
    assert np.allclose(a, b, rtol=1e-9, atol=1e-9)


def _typed_options():
    """(command words, option, type) of every option of every sub-command that converts a value."""
    def walk(parser, words):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    yield from walk(sub, words + [name])
            elif action.option_strings and (action.type in (types.positive, types.finite,
                                                            types.count, float, int)
                                            or getattr(action.type, "__name__", "") in RANGES):
                yield words, action.option_strings[-1], action.type
    return list(walk(cli.build_parser(), []))


@pytest.mark.parametrize("bad", ["nan", "inf", "-1", "abc", ""])
def test_every_numeric_option_refuses_malformed_values(bad, capsys):
    options = _typed_options()
    assert len(options) > 40 and not [o for o in options if o[2] is float]
    for words, option, kind in options:
        signed = kind in (types.finite, int) or getattr(kind, "__name__", "") in RANGES and RANGES[kind.__name__].low < 0
        if signed and bad == "-1":
            continue    # a signed value (a coordinate, a seed): -1 is valid
        with pytest.raises(SystemExit) as exit_info:
            cli.main(words + [option, bad])
        err = capsys.readouterr().err
        assert exit_info.value.code == 2, (words, option, bad)
        assert "Traceback" not in err and option.lstrip("-") in err.replace("_", "-"), (words, option, bad, err)


def test_psd_in_metres_is_refused(tmp_path, capsys):
    psd = tmp_path / "metres.csv"
    psd.write_text("diameter_um,percent_finer\n2.5e-6,0\n7e-5,100\n")
    assert cli.main(["sample", str(psd), "--out", str(tmp_path / "out")]) == 2
    assert "write micrometres, not metres" in capsys.readouterr().err


def test_every_help_works_before_the_core_is_built_and_a_command_says_what_to_build(tmp_path):
    shutil.copytree(REPO / "python" / "sediment", tmp_path / "sediment",
                    ignore=shutil.ignore_patterns("_core*.so", "__pycache__"))
    def bare(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run(["/usr/bin/python3", "-m", "sediment", *args], capture_output=True, text=True,
                              cwd=tmp_path, env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(tmp_path)})
    for command in [[]] + [[c] for c in cli.build_parser()._subparsers._group_actions[0].choices]:
        done = bare(*command, "--help")
        assert done.returncode == 0 and "Traceback" not in done.stderr, (command, done.stderr)
    done = bare("terminal", "--diameter", "1e-4", "--particle-density", "2650")
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "not built: run `make build`" in done.stderr
    done = bare("--version")    # the release is the core's
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "not built: run `make build`" in done.stderr


def test_the_commands_come_in_the_order_of_the_work_with_examples_that_parse(capsys):
    parser = cli.build_parser()
    names = list(parser._subparsers._group_actions[0].choices)
    assert names[:6] == ["plan", "sample", "run", "readout", "budget", "invert"]
    with pytest.raises(SystemExit) as done:
        parser.parse_args(["--version"])
    assert done.value.code == 0 and capsys.readouterr().out.strip() == f"sediment {sediment.__version__}"
    for command in cli.COMMANDS:
        assert command.EXAMPLES
        for line in command.EXAMPLES:
            words = shlex.split(line.split("#")[0])
            assert words[0] == "sediment"
            parser.parse_args(words[1:])    # exits with the reason if an example does not parse
            for word in words:
                if word.startswith(("examples/", "tests/data/")):
                    assert (REPO / word).exists(), line
    text = parser._subparsers._group_actions[0].choices["sample"].format_help()
    assert "(default: 0.06)" in text and "(default: None)" not in text and "examples:\n  sediment sample" in text


def test_the_names_the_help_offers_are_the_cores():
    from sediment import _core
    from sediment.constants import DRAG_LAWS

    assert list(DRAG_LAWS) == _core.drag_law_names()


def test_the_core_stub_matches_the_built_module():
    import runpy

    from sediment import _core

    stub = runpy.run_path(str(REPO / "scripts" / "core-stub.py"))["stub_text"](_core)
    assert (REPO / "python" / "sediment" / "_core.pyi").read_text() == stub, "run scripts/core-stub.py"
    assert (REPO / "python" / "sediment" / "py.typed").is_file()


def test_a_signal_whose_interrupt_was_lost_still_stops_the_command(tmp_path, monkeypatch, capsys):
    """A SIGINT that lands in a finaliser (a weak reference's callback, as the hostile round caught in
    invert's fit) raises its KeyboardInterrupt there, where Python goes on: the command must still end
    with 130, publish nothing and say so in one line, without Python's "Exception ignored" traceback."""
    import signal

    from sediment.cli import readout

    real = readout.run

    class Finalised:
        def __del__(self):
            signal.raise_signal(signal.SIGINT)    # the handler raises here, and Python cannot

    def swallowed(args):
        Finalised()                               # made and finalised at once: the interrupt is lost
        return real(args)
    monkeypatch.setattr(readout, "run", swallowed)
    psd = Path(__file__).resolve().parents[2] / "examples" / "granulometry" / "psd" / "sample5.csv"
    out = tmp_path / "preview"
    monkeypatch.setattr(sys, "unraisablehook", sys.__unraisablehook__)    # Python's own, which prints (not pytest's)
    hook = sys.unraisablehook
    assert cli.main(["readout", "--psd", str(psd), "--stokes-preview", "--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert "interrupted by SIGINT" in err and "Traceback" not in err and "Exception ignored" not in err
    assert sys.unraisablehook is hook    # the hook the command found, again after it
    assert not out.exists() or not any(p for p in out.iterdir() if not p.name.startswith(".sediment"))


@pytest.mark.parametrize("value", ["-1e-3", "-1e-3,1e-3", "-.5E+2", "-0.001,-2"])
def test_a_negative_number_in_e_notation_reaches_its_option_s_check(value, capsys):
    """argparse took '-1e-3' (and a list starting with it) for an option and said only that --dt had
    no value; the option's own check now names the value."""
    with pytest.raises(SystemExit) as stop:
        cli.main(["sweep", "deck.lmp", "--dt", value, "--observe", "x"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "argument --dt: must be > 0" in err and "expected one argument" not in err
    assert cli.NEGATIVE_NUMBER.match(value)
    assert not any(cli.NEGATIVE_NUMBER.match(option) for option in ("--dt", "-h", "-1e", "-1e-3,x", "-e3"))


def test_an_interrupt_a_library_turned_into_its_own_error_still_stops_the_command(tmp_path, monkeypatch, capsys):
    """numpy's import turns a KeyboardInterrupt into "ImportError: numpy.core.multiarray failed to import"
    (hostile round, SIGINT as `sample` loaded): the command ends with 130 and says it was interrupted, not
    a traceback or an error about the input."""
    import signal

    from sediment.cli import readout

    def broken(args):
        try:
            signal.raise_signal(signal.SIGINT)
        except KeyboardInterrupt:
            raise ImportError("numpy.core.multiarray failed to import") from None
    monkeypatch.setattr(readout, "run", broken)
    psd = Path(__file__).resolve().parents[2] / "examples" / "granulometry" / "psd" / "sample5.csv"
    out = tmp_path / "preview"
    assert cli.main(["readout", "--psd", str(psd), "--stokes-preview", "--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert "interrupted by SIGINT" in err and "Traceback" not in err and "ImportError" not in err
