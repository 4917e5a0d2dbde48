"""A hostile robustness corpus for mbsuite: hundreds of bad inputs, each run as a subprocess and classified.

mbsuite promises that every failure exits 2 with one line on stderr naming the bad input (under `--json` also a JSON
object `{"error": {...}}` on stdout), that Ctrl-C exits 130 without a traceback, that a closed pipe is quiet, that legal
but enormous jobs are refused by size guards, that a run whose health figures exceed their bounds is an error unless
`--allow-inaccurate`, and that the sweep store is never executed. This script attacks those promises.

Each attempt declares its area, its command (a command line of `python -m mbsuite.cli`, or a Python snippet using the
documented API) and what is expected:

- `error`: exit 2 with exactly one stderr line starting `mbsuite: error:` (command lines) or with the name of an
  mbsuite exception class (snippets), naming the attempt's culprit where it has one;
- `ok`: exit 0 and, for JSON output, no NaN/Infinity and no null among numbers;
- `either`: a clear error or ok (for inputs a program may reasonably refuse or repair, e.g. a damaged store line);
  in both cases forbidden text (a forged value) must not reach stdout and forbidden files (the mark of an executed
  payload) must not appear.

Outcomes: `ok`, `clear` (clear error), `culprit` (an error naming the wrong culprit), `unclear` (exit 2 without the one
promised line or without the JSON error object), `trace` (exit 1 or a traceback on stderr), `silent` (exit 0 where an
error was expected, NaN/null in the output, a forged value served or a payload executed), `refused` (an error where
success was expected), `hang` (timeout), `crash` (killed, or an unexpected exit status), `setup` (the attempt's own
preparation failed: a fault of this script, not of mbsuite). Passing: `ok` and `clear`.

    python scripts/robustness_corpus.py --workers 2 --json-out /tmp/corpus.json
    python scripts/robustness_corpus.py --pythonpath /tmp/other_checkout --area store,scene
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import dataclasses
import json
import math
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from pathlib import Path

AREAS = ("scene", "model", "cli", "numerics", "store", "signals", "threads", "declared")
OUTCOMES = ("ok", "clear", "culprit", "unclear", "trace", "silent", "refused", "hang", "crash", "setup")
PASSING = ("ok", "clear")
DIR = "@DIR@"  # replaced by the attempt's scratch directory in argv, snippets, setup code, files and environment
MEMORY_LIMIT = 6 << 30

# The harness around a snippet: an mbsuite exception becomes one line "ClassName: message" and exit 2; an
# AssertionError (a snippet's own check found a wrong result) becomes "SILENT: ..." and exit 3; anything else a
# traceback and exit 1. A snippet exits 4 itself when the command it drives does not respond in time (a hang).
HARNESS = textwrap.dedent("""\
    import sys, traceback
    _src = open(sys.argv[1], encoding="utf-8").read()
    try:
        exec(compile(_src, "<attempt>", "exec"), {"__name__": "__attempt__"})
    except SystemExit:
        raise
    except AssertionError as _exc:
        print(f"SILENT: {_exc}", file=sys.stderr)
        sys.exit(3)
    except BaseException as _exc:
        try:
            import mbsuite
            _ours = isinstance(_exc, mbsuite.MbsuiteError)
        except Exception:
            _ours = False
        if _ours:
            print(f"{type(_exc).__name__}: {_exc}", file=sys.stderr)
            sys.exit(2)
        traceback.print_exc()
        sys.exit(1)
    """)


@dataclass(frozen=True)
class Attempt:
    """One hostile attempt: a command line (`argv`, after `python -m mbsuite.cli`) or a Python `snippet`."""

    name: str
    area: str
    what: str
    expect: str  # "error" | "ok" | "either"
    argv: tuple[str, ...] = ()
    snippet: str = ""
    culprit: str | None = None  # alternatives separated by "|", matched case-insensitively in the error line
    files: tuple[tuple[str, bytes], ...] = ()  # scratch files (relative path, content) written before the run
    setup: str = ""  # Python code run before the command (same interpreter and environment)
    env: tuple[tuple[str, str], ...] = ()
    forbid_stdout: tuple[str, ...] = ()
    forbid_files: tuple[str, ...] = ()
    timeout: float | None = None

    def command(self) -> list[str] | str:
        return list(self.argv) if not self.snippet else self.snippet


@dataclass
class Outcome:
    """What one attempt did."""

    name: str
    area: str
    what: str
    expect: str
    culprit: str | None
    command: list[str] | str
    outcome: str
    exit_code: int | None
    seconds: float
    last_line: str
    detail: str = ""
    stderr_tail: list[str] = field(default_factory=list)


# ---------------------------------------------------------------------------------------------------- scene texts
PANTO = """model = "pantograph"
[effects]
cylinder = "linear"
coulomb = true
contact = "bilateral"
[input]
type = "sine"
amplitude = 1.85e-3
frequency = 4.25
[solver]
engine = "mujoco"
integrator = "rk4"
timestep = 1e-3
duration = 2.0
t_settle = 1.0
"""

MODEL_SCENES = {
    "pantograph": PANTO,
    "coupler": """model = "coupler"
[input]
type = "constant_speed"
omega = 12.566370614359172
[solver]
engine = "mujoco"
duration = 1.0
t_settle = 0.5
""",
    "drives": """model = "drives"
[effects]
mechanism = "step_up"
controller = "pwm"
[params]
duty = 0.5
t_l = 0.2
[input]
type = "reference"
[solver]
engine = "mujoco"
duration = 1.0
t_settle = 0.5
""",
    "iftomm": """model = "iftomm"
[effects]
mechanism = "fourbar"
[input]
type = "initial"
rate = 6.0
[solver]
engine = "mujoco"
duration = 2.0
""",
    "catenary": """model = "catenary"
[params]
element_length = 0.5
[input]
type = "passage"
speed = 250.0
[solver]
engine = "reference"
timestep = 2e-4
""",
}


def with_lines(base: str, section: str | None, lines: str) -> str:
    """`base` with `lines` added to `[section]` (created if missing), or at the top for `section=None`."""
    if section is None:
        return lines + "\n" + base
    head = f"[{section}]\n"
    if head in base:
        return base.replace(head, head + lines + "\n", 1)
    return base + head + lines + "\n"


def scene(name: str, area: str, what: str, text: str | bytes, expect: str = "error", culprit: str | None = None,
          cmd: tuple[str, ...] = ("run",), extra: tuple[str, ...] = ("--json",), timeout: float | None = None,
          ) -> Attempt:
    """A scene file in the scratch directory run by `mbsuite <cmd> FILE <extra>`."""
    data = text.encode() if isinstance(text, str) else text
    return Attempt(name, area, what, expect, (*cmd, f"{DIR}/scene.toml", *extra), culprit=culprit,
                   files=(("scene.toml", data),), timeout=timeout)


def cli(name: str, area: str, what: str, argv: str | tuple[str, ...], expect: str = "error",
        culprit: str | None = None, **kw) -> Attempt:
    """A command line of mbsuite (`argv` as a tuple, or a string split on spaces)."""
    args = tuple(argv.split()) if isinstance(argv, str) else argv
    return Attempt(name, area, what, expect, args, culprit=culprit, **kw)


def snip(name: str, area: str, what: str, code: str, expect: str = "error", culprit: str | None = None,
         **kw) -> Attempt:
    """A Python snippet run under the harness (mbsuite exceptions -> exit 2 and one line)."""
    return Attempt(name, area, what, expect, snippet=textwrap.dedent(code), culprit=culprit, **kw)


# ---------------------------------------------------------------------------------------------------- the corpus
def scene_attempts() -> Iterator[Attempt]:
    """Scene files: syntax, encodings, types, non-finite and out-of-range values, unknown keys, wrong section types."""
    a = "scene"
    yield scene("scene-ok-control", a, "a valid short pantograph scene (control)", PANTO, "ok")
    yield scene("scene-ok-drives-profile", "signals", "a valid step_up_down profile scene (control)",
                MODEL_SCENES["drives"].replace('mechanism = "step_up"', 'mechanism = "step_up_down"').replace(
                    'controller = "pwm"', 'controller = "energy_packet"\nclosed_loop = true').replace(
                    "duty = 0.5\nt_l = 0.2\n", 'set = "design_100w"\n').replace(
                    'type = "reference"\n',
                    'type = "reference"\nprofile = [[0.0, 300.0], [0.5, 300.0], [1.0, 200.0]]\n'),
                "ok", timeout=120)
    for model, text in MODEL_SCENES.items():
        if model not in ("catenary", "pantograph"):
            yield scene(f"scene-ok-{model}", a, f"a valid short {model} scene (control)", text, "ok", timeout=120)
    yield scene("empty-file", a, "an empty scene file", "", culprit="model")
    yield scene("comments-only", a, "only comments", "# nothing\n# here\n", culprit="model")
    yield scene("toml-no-value", a, "key without a value", "model = \n", culprit="TOML")
    yield scene("toml-unclosed-table", a, "unclosed table header", PANTO.replace("[solver]", "[solver"),
                culprit="TOML")
    yield scene("toml-duplicate-key", a, "a key given twice", with_lines(PANTO, "solver", "timestep = 2e-3"),
                culprit="TOML|timestep")
    yield scene("toml-unclosed-string", a, "an unterminated string", 'model = "pantograph\n', culprit="TOML")
    yield scene("toml-bad-escape", a, "invalid string escape", 'model = "pan\\qtograph"\n', culprit="TOML")
    yield scene("toml-duplicate-table", a, "a table given twice", PANTO + "[solver]\nduration = 1.0\n",
                culprit="TOML|solver")
    yield scene("binary-garbage", a, "random bytes", bytes(range(256)) * 4, culprit="UTF-8|scene.toml")
    yield scene("latin1", a, "a Latin-1 encoded description (not UTF-8)",
                with_lines(PANTO, None, 'description = "caf\u00e9 cr\u00e8me"').encode("latin-1"), culprit="UTF-8")
    yield scene("utf16", a, "a UTF-16 encoded scene", PANTO.encode("utf-16"), culprit="UTF-8|TOML")
    yield scene("utf8-bom", a, "UTF-8 with a byte-order mark", b"\xef\xbb\xbf" + PANTO.encode(), "either",
                culprit="TOML|scene.toml")
    yield scene("nul-bytes", a, "NUL bytes inside the file", PANTO.encode().replace(b"[input]", b"[in\x00put]"),
                culprit="TOML|scene.toml")
    yield scene("huge-file", a, "a 2 MB scene (comment padding)", PANTO + ("#" + "x" * 1000 + "\n") * 2000,
                culprit="bytes")
    yield scene("deep-nesting", a, "params value nested 5000 arrays deep (parser recursion)",
                with_lines(PANTO, None, "") + "[params]\nm1 = " + "[" * 5000 + "]" * 5000 + "\n",
                culprit="m1|TOML|scene.toml")
    yield scene("long-key", a, "a 20 000-character unknown key", with_lines(PANTO, None, "k" * 20000 + " = 1"),
                culprit="kkkk")
    yield cli("missing-file", a, "a .toml path that does not exist", f"run {DIR}/nope.toml", culprit="nope.toml")
    yield cli("directory-toml", a, "a directory whose name ends .toml", f"run {DIR}/d.toml", culprit="d.toml",
              setup=f"import os; os.mkdir('{DIR}/d.toml')")
    yield cli("directory-plain", a, "a directory as the scene", f"run {DIR}", culprit=Path(DIR).name or "@DIR@")
    yield cli("fifo-scene", a, "a named pipe as the scene file (a read would block)", f"run {DIR}/p.toml --json",
              culprit="p.toml", setup=f"import os; os.mkfifo('{DIR}/p.toml')", timeout=30)
    yield scene("model-unknown", a, "unknown model", PANTO.replace('"pantograph"', '"nosuch"'), culprit="nosuch")
    yield scene("model-int", a, "model = 42", PANTO.replace('"pantograph"', "42"), culprit="model")
    yield scene("model-empty", a, 'model = ""', PANTO.replace('"pantograph"', '""'), culprit="model")
    yield scene("model-path-traversal", a, 'model = "../../etc"', PANTO.replace('"pantograph"', '"../../etc"'),
                culprit="../../etc|model")
    yield scene("unknown-top-key", a, "unknown top-level key", with_lines(PANTO, None, "foo = 1"), culprit="foo")
    yield scene("name-int", a, "name = 5", with_lines(PANTO, None, "name = 5"), culprit="name")
    yield scene("description-list", a, "description = [1]", with_lines(PANTO, None, "description = [1]"),
                culprit="description")
    for sec, val in (("effects", '"x"'), ("params", "[1, 2]"), ("solver", "5"), ("input", "true"),
                     ("outputs", '"F1"')):
        yield scene(f"section-{sec}-not-table", a, f"{sec} = {val} (a value, not a table)",
                    f'model = "pantograph"\n{sec} = {val}\n', culprit=sec)
    yield scene("array-of-tables", a, "[[solver]] (an array of tables)", PANTO.replace("[solver]", "[[solver]]"),
                culprit="solver")
    yield scene("signals-string", a, 'outputs.signals = "F1"', PANTO + '[outputs]\nsignals = "F1"\n',
                culprit="signals")
    yield scene("signals-ints", a, "outputs.signals = [1, 2]", PANTO + "[outputs]\nsignals = [1, 2]\n",
                culprit="signals")
    yield scene("signals-unknown", a, "an unknown output signal", PANTO + '[outputs]\nsignals = ["nope"]\n',
                culprit="nope")
    yield scene("signals-empty", a, "outputs.signals = [] (nothing to record)", PANTO + "[outputs]\nsignals = []\n",
                "either", culprit="signals")
    yield scene("outputs-extra-key", a, "unknown key in [outputs]", PANTO + "[outputs]\nextra = 1\n",
                culprit="extra")
    yield scene("effect-unknown", a, "unknown effect", with_lines(PANTO, "effects", "cylinder2 = true"),
                culprit="cylinder2")
    yield scene("effect-bad-value", a, "cylinder = quadratic", PANTO.replace('"linear"', '"quadratic"'),
                culprit="cylinder")
    yield scene("effect-int-for-bool", a, "coulomb = 1", PANTO.replace("coulomb = true", "coulomb = 1"),
                culprit="coulomb")
    yield scene("effect-string-for-bool", a, 'gravity = "yes"', with_lines(PANTO, "effects", 'gravity = "yes"'),
                culprit="gravity")
    yield scene("effect-table", a, "effect given a table", with_lines(PANTO, "effects", "viscous = {a = 1}"),
                culprit="viscous")
    for model, eff, val in (("coupler", "friction", '"yes"'), ("drives", "controller", '"pid"'),
                            ("iftomm", "mechanism", '"stewart"'), ("catenary", "droppers", '"rigid"'),
                            ("catenary", "pantograph", '"faiveley"')):
        yield scene(f"effect-{model}-{eff}", a, f"{model}: {eff} = {val}",
                    with_lines(MODEL_SCENES[model], "effects", f"{eff} = {val}"), culprit=eff)
    yield scene("param-drives-set", a, 'drives: [params] set = "table_9_9"',
                with_lines(MODEL_SCENES["drives"], "params", 'set = "table_9_9"'), culprit="set")
    rot = 'model = "rotational"\n[effects]\nexample = "coupled_clutches"\n'
    yield scene("effect-rotational-example", a, 'rotational: example = "clutchless"',
                rot.replace('"coupled_clutches"', '"clutchless"'), culprit="example")
    yield scene("param-rotational-any", a, "rotational: a [params] key (the examples carry the MSL's own)",
                rot + "[params]\nJ1 = 2.0\n", culprit="J1")
    yield scene("effect-drives-modelica-mechanism", a, 'drives: mechanism = "coupled_clutches" (now its own model)',
                with_lines(MODEL_SCENES["drives"], "effects", 'mechanism = "coupled_clutches"'), culprit="mechanism")
    yield scene("param-unknown", a, "unknown parameter", PANTO + "[params]\nmass = 3.0\n", culprit="mass")
    for p, v, why in (("l1", "nan", "NaN"), ("l1", "inf", "infinite"), ("l1", "-inf", "minus infinity"),
                      ("l1", "-1.95", "negative length"), ("l1", "0.0", "zero length"), ("m1", '"heavy"', "a string"),
                      ("m1", "true", "a boolean"), ("m1", "[1.0]", "a list"), ("m1", "{a = 1}", "a table"),
                      ("ks", "1e309", "overflows to inf"), ("y_op", "5.0", "unreachable height"),
                      ("d1", "3.0", "mass centre beyond the link"), ("gamma", "2.5", "outside (1, 2)"),
                      ("cd", "0.0", "zero discharge coefficient"), ("m1", "1e300", "absurd mass"),
                      ("g", "-9.81", "negative gravity"), ("omega_s", "0.0", "zero smoothing scale"),
                      ("r_laminar", "0.1", "below the choked ratio"), ("Pg", "1e-300", "vanishing supply pressure"),
                      ("I1", "1e-320", "denormal inertia")):
        legal = p in ("Pg", "I1")  # tiny but positive: a program may run it
        yield scene(f"param-pantograph-{p}-{why.replace(' ', '_')}", a, f"pantograph {p} = {v} ({why})",
                    PANTO + f"[params]\n{p} = {v}\n", "either" if legal else "error", culprit=p)
    for model, p, v, why in (
            ("coupler", "gamma", "1.0", "above pi over 4"), ("coupler", "e_y", "-1.0", "negative shift"),
            ("coupler", "l_b", "0.01", "shorter than two link radii"), ("coupler", "R", "nan", "NaN radius"),
            ("coupler", "m_link", "0", "massless link"), ("coupler", "solref_dampratio", "-1", "negative damping"),
            ("coupler", "gamma", "1e-300", "degenerate gamma"),
            ("drives", "J_m", "0.0", "zero motor inertia"), ("drives", "duty", "1.5", "duty above 1"),
            ("drives", "tau_slope", "1.0", "torque rising with speed"), ("drives", "K", "nan", "NaN stiffness"),
            ("drives", "fs", "-500.0", "negative sample rate"), ("drives", "peak", "0.5", "peak below 1"),
            ("drives", "fs", "1e12", "absurd sample rate"), ("drives", "J_l", '"big"', "a string"),
            ("iftomm", "gravity", "-9.81", "negative gravity"), ("iftomm", "solref_timeconst", "0.0", "zero"),
            ("iftomm", "penalty", "inf", "infinite penalty"), ("iftomm", "penalty_omega", "1e7", "above limit"),
            ("catenary", "n_spans", "0", "no spans"), ("catenary", "span_length", "-60.0", "negative span"),
            ("catenary", "element_length", "0.0", "zero element"), ("catenary", "n_spans", "1.5", "fractional"),
            ("catenary", "dropper_positions", "[70.0]", "dropper beyond the span"),
            ("catenary", "dropper_positions", '["a"]', "a string dropper"),
            ("catenary", "filter_order", "0", "zero filter order"), ("catenary", "window_start", "400.0",
                                                                     "window start after its end"),
            ("catenary", "x_end", "-10.0", "end before start"), ("catenary", "cw_tension", "nan", "NaN tension"),
            ("catenary", "zeta", "-0.1", "negative damping")):
        yield scene(f"param-{model}-{p}-{why.replace(' ', '_')}", a, f"{model} {p} = {v} ({why})",
                    with_lines(MODEL_SCENES[model], "params", f"{p} = {v}"),
                    "either" if why == "degenerate gamma" else "error", culprit=p)
    for sec, key, val, cul in (
            ("solver", "integrator", '"rk5"', "integrator"), ("solver", "engine", '"bullet"', "engine"),
            ("solver", "method", '"magic"', "method"), ("solver", "timestep", '"1e-3"', "timestep"),
            ("solver", "timestep", "true", "timestep"), ("solver", "steps", "10", "steps"),
            ("solver", "allow_inaccurate", '"yes"', "allow_inaccurate"), ("solver", "engine", "1", "engine"),
            ("solver", "max_steps", '"big"', "max_steps")):
        text = PANTO.replace(f"{key} = ", f"#{key} = ") if f"\n{key} = " in PANTO else PANTO
        yield scene(f"solver-{key}-{val.strip(chr(34))}", a, f"solver.{key} = {val}",
                    with_lines(text, sec, f"{key} = {val}"), culprit=cul)


def solver_value_attempts() -> Iterator[Attempt]:
    """Every numeric solver setting: NaN, infinities, zero, negative, past its declared range."""
    base = "\n".join(ln for ln in PANTO.splitlines() if not ln.startswith(("timestep", "duration", "t_settle")))
    defaults = {"timestep": "1e-3", "duration": "2.0", "t_settle": "1.0"}
    cases = {
        "timestep": ("nan", "inf", "-inf", "0.0", "-1e-3", "5e-324"),
        "duration": ("nan", "inf", "0.0", "-1.0", "1e6"),
        "t_settle": ("nan", "-1.0", "2.0", "1e9"),
        "rtol": ("nan", "0.0", "1.0", "-1e-8"),
        "atol": ("nan", "0.0", "-1.0", "inf"),
        "max_step": ("nan", "-1.0", "2.0"),
        "sample_dt": ("nan", "-1.0", "20.0", "inf"),
        "max_steps": ("nan", "0.0", "-5.0", "1e13", "inf"),
    }
    for key, values in cases.items():
        for v in values:
            vals = dict(defaults)
            vals[key] = v
            lines = "\n".join(f"{k} = {x}" for k, x in vals.items())
            yield scene(f"solver-{key}={v}", "scene", f"solver.{key} = {v}", with_lines(base, "solver", lines),
                        culprit=key)


def input_attempts() -> Iterator[Attempt]:
    """Scene inputs (waveforms) with bad parameters, for every model."""
    a = "signals"
    no_input = PANTO.split("[input]")[0] + "[solver]" + PANTO.split("[solver]")[1]
    for key, v, why in (("amplitude", "nan", "NaN"), ("amplitude", "inf", "infinite"),
                        ("amplitude", '"big"', "a string"), ("amplitude", "10.0", "10 m"),
                        ("frequency", "nan", "NaN"), ("frequency", "-4.25", "negative"),
                        ("frequency", "1e6", "1 MHz"), ("frequency", "[4.25]", "a list"),
                        ("initial", '"bogus"', "unknown initial state"), ("initial", "3", "a number"),
                        ("phase", "0.5", "an undeclared key")):
        values = {"amplitude": "1.85e-3", "frequency": "4.25", key: v}
        lines = "".join(f"{k} = {x}\n" for k, x in values.items())
        text = no_input.replace("[solver]", f'[input]\ntype = "sine"\n{lines}[solver]')
        yield scene(f"sine-{key}-{why.replace(' ', '_')}", a, f"pantograph sine input {key} = {v} ({why})", text,
                    culprit=key)
    yield scene("input-type-unknown", a, "input type square", PANTO.replace('type = "sine"', 'type = "square"'),
                culprit="square")
    yield scene("input-type-int", a, "input type = 3", PANTO.replace('type = "sine"', "type = 3"), culprit="type")
    yield scene("input-nested", a, "a nested table in [input]", PANTO + "[input.shape]\nk = 1\n",
                culprit="shape")
    step = no_input.replace("[solver]", '[input]\ntype = "step"\nheight = H\nt_step = T\n[solver]')
    for h, t, why in (("nan", "0.5", "NaN height"), ("5.0", "0.5", "5 m step"), ("1e-3", "-1.0", "negative time"),
                      ("1e-3", "1e9", "step after the end"), ("1e-3", "nan", "NaN time"),
                      ("inf", "0.5", "infinite height")):
        yield scene(f"step-{why.replace(' ', '_')}", a, f"pantograph step input height={h}, t_step={t} ({why})",
                    step.replace("H", h).replace("T", t), "either" if "after the end" in why else "error",
                    culprit="height" if h != "1e-3" else "t_step")
    cp = MODEL_SCENES["coupler"]
    for key, v in (("omega", "0.0"), ("omega", "-12.0"), ("omega", "1e4"), ("load_torque", "nan"),
                   ("load_torque", "1e8"), ("t_ramp", "-1.0"), ("alpha_cx", "1.0"), ("z_c", "inf"),
                   ("omega", '"fast"'), ("spin", "1.0")):
        text = cp.replace("omega = 12.566370614359172", f"{key} = {v}") if key == "omega" else \
            with_lines(cp, "input", f"{key} = {v}")
        yield scene(f"coupler-input-{key}={v.strip(chr(34))}", a, f"coupler constant_speed {key} = {v}", text,
                    culprit=key)
    dr = MODEL_SCENES["drives"]
    # a reference acts only closed loop (open loop the step-up refuses input.value): the PI on t_k tracks it
    dr_cl = dr.replace('controller = "pwm"', 'controller = "pwm"\nclosed_loop = true')
    yield scene("scene-ok-drives-closed-loop", a, "a valid closed-loop step-up scene at 287 rad/s (control)",
                with_lines(dr_cl, "input", "value = 287.0"), "ok", timeout=120)
    yield scene("drives-value-open-loop", a, "drives open-loop pwm with input.value = 287 (no reference acts)",
                with_lines(dr, "input", "value = 287.0"), culprit="value")
    for v, why, cul in (("nan", "NaN reference", "value"), ('"fast"', "a string reference", "value"),
                        ("-1e9", "absurd negative reference", "value"), ("inf", "infinite reference", "value")):
        yield scene(f"drives-value-{why.replace(' ', '_')}", a, f"drives reference value = {v} ({why})",
                    with_lines(dr_cl, "input", f"value = {v}"), culprit=cul)
    for prof, why in (("[[0.0]]", "rows of one number"), ("[[1.0, 2.0], [0.0, 3.0]]", "times going back"),
                      ('"abc"', "a string"), ("[]", "empty"), ("[[0.0, nan], [1.0, 2.0]]", "NaN value"),
                      ("[[0.0, 1.0, 2.0]]", "rows of three")):
        susd = dr.replace('mechanism = "step_up"', 'mechanism = "step_up_down"').replace(
            'controller = "pwm"', 'controller = "energy_packet"\nclosed_loop = true').replace(
            "duty = 0.5\nt_l = 0.2\n", 'set = "design_100w"\n')
        yield scene(f"drives-profile-{why.replace(' ', '_')}", a, f"drives step_up_down reference profile = {prof} "
                    f"({why})", with_lines(susd, "input", f"profile = {prof}"), culprit="profile")
    it = MODEL_SCENES["iftomm"]
    for v in ("1000.0", "nan", "-1e3", '"spin"'):
        yield scene(f"iftomm-rate={v.strip(chr(34))}", a, f"iftomm initial rate = {v}",
                    it.replace("rate = 6.0", f"rate = {v}"), culprit="rate")
    ca = MODEL_SCENES["catenary"]
    for v in ("0.0", "-100.0", "nan", "1e6", '"fast"', "inf"):
        yield scene(f"catenary-speed={v.strip(chr(34))}", a, f"catenary passage speed = {v} km/h",
                    ca.replace("speed = 250.0", f"speed = {v}"), culprit="speed")
    aero = '\n[aerodynamics]\nrunning = "knuckle-leading"\nknuckle_leading = {{ head = {h}, frame = 0.0037 }}\n'
    for v, culprit in (("-0.002", "head"), ("nan", "head"), ('"high"', "head"), ("2.0", "head")):
        yield scene(f"catenary-aero-head={v.strip(chr(34))}", a, f"aerodynamic head coefficient = {v}",
                    ca + aero.format(h=v), culprit=culprit)
    yield scene("catenary-aero-missing-case", a, "running knuckle-trailing without its coefficients",
                ca + aero.format(h="0.0024").replace('running = "knuckle-leading"', 'running = "knuckle-trailing"'),
                culprit="knuckle_trailing")
    yield scene("catenary-aero-unknown-key", a, "an unknown key in [aerodynamics]",
                ca + aero.format(h="0.0024") + "drag = 0.1\n", culprit="drag")
    ov = ca.replace("[params]\n", '[params]\nwindows = [[120.0, 300.0], [300.0, 480.0]]\n')
    yield scene("catenary-windows-outside-run", a, "statistics windows outside the run", ov, culprit="windows")
    yield scene("catenary-windows-reversed", a, "a statistics window ending before it starts",
                ca.replace("[params]\n", '[params]\nwindows = [[300.0, 240.0]]\n'), culprit="windows")
    yield scene("catenary-step-sections-unknown", a, "a route's stepped sections named by an unknown word",
                ca.replace("[params]\n", '[params]\nstep_sections = "some"\n'), culprit="step_sections")
    route = ca.replace("[params]\n", '[line]\nkind = "overlap"\n\n[line.overlap]\nsections = 3\nspans = 5\n'
                       'overlap_spans = 3\n\n[params]\n')
    yield scene("catenary-route-overlaps-cross", a, "three sections whose inner one's two overlaps would cross", route,
                culprit="overlap_spans")
    yield scene("catenary-route-insulator-unknown-wire", a, "a scene's section insulator on a wire the route has not",
                route.replace("spans = 5\noverlap", "spans = 8\noverlap")
                + '\n[[line.insulators]]\nx = 400.0\nwire = "contact_x"\nlength = 2.0\nmass = 8.0\nEI = 2000.0\n',
                culprit="contact_x")
    from mbsuite.models.catenary.linefile import EXAMPLE  # a line file with a section insulator on [69, 71] m

    for tag, what, change, culprit in (
            ("off-the-wire", "a section insulator reaching past the contact wire's end", {"x": 99.5}, "insulator"),
            ("negative-length", "a section insulator of negative length", {"length": -2.0}, "length"),
            ("overlapping", "two section insulators overlapping on one wire", None, "overlap")):
        data = copy.deepcopy(EXAMPLE)
        if change is None:
            data["insulators"].append({**data["insulators"][0], "x": 70.5})
        else:
            data["insulators"][0].update(change)
        yield Attempt(f"catenary-line-insulator-{tag}", a, what, "error", ("catenary", f"{DIR}/input.toml", "--json"),
                      culprit=culprit, files=(("input.toml", toml_text(data).encode()),))
    api = {
        "sine-nan-frequency": ("Sine(frequency=float('nan'))", "frequency"),
        "sine-inf-amplitude": ("Sine(amplitude=float('inf'))", "amplitude"),
        "sine-string-phase": ("Sine(phase='x')", "phase"),
        "step-nan-t0": ("Step(t0=float('nan'))", "t0"),
        "ramp-negative-duration": ("Ramp(duration=-1.0)", "duration"),
        "ramp-inf-height": ("Ramp(height=float('inf'))", "height"),
        "pulse-width-2": ("Pulse(width=2.0)", "width"),
        "pulse-zero-period": ("Pulse(period=0.0)", "period"),
        "pulse-negative-n": ("Pulse(n=-1)", "n =|n >=|n must"),
        "pulse-fractional-n": ("Pulse(n=1.5)", "n =|n >=|n must|integer"),
        "table-empty": ("Table((), ())", "table"),
        "table-length-mismatch": ("Table((0.0, 1.0), (1.0,))", "table"),
        "table-times-back": ("Table((1.0, 0.0), (0.0, 1.0))", "table"),
        "table-strings": ("Table(('a',), (1.0,))", "table"),
        "table-nan": ("Table((0.0, float('nan')), (0.0, 1.0))", "table"),
        "constant-string": ("Constant('x')", "value"),
        "constant-none": ("Constant(None)", "value"),

    }
    for name, (expr, cul) in api.items():
        code = f"""
            import numpy as np
            from mbsuite.engines.inputs import *
            s = {expr}
            y = s(np.linspace(0.0, 1.0, 11))
            assert np.all(np.isfinite(y)), f"non-finite signal values {{y}}"
            print(s.spec())
            """
        yield snip(f"api-{name}", a, f"mbsuite.engines.inputs.{expr}", code, culprit=cul)


# ------------------------------------------------------------------------------------------------- model files
COPY_MODELS = f"""
import os, pathlib, re, shutil
import mbsuite.paths as P
os.environ.pop("MBSUITE_MODELS_DIR", None)  # the shipped files, whatever the attempt will set
root = P.models_root()
dst = pathlib.Path("{DIR}/models")
shutil.copytree(root / "mjcf", dst / "mjcf")
shutil.copytree(root / "models_urdf", dst / "models_urdf")
def edit(rel, old, new, count=1):
    f = dst / rel
    text = f.read_text()
    assert old in text, f"{{old!r}} not in {{f}}"
    f.write_text(text.replace(old, new, count))
"""
ROCKER_5M = COPY_MODELS + """
edit("mjcf/iftomm_fourbar.xml", '<body name="rocker" pos="1 0 0">', '<body name="rocker" pos="5 0 0">')
"""
COUPLER_LINK = COPY_MODELS + """
L = "0.944253246252565"
edit("models_urdf/coupler_single.urdf", f'frame_b="B_S2" length="{L}"', 'frame_b="B_S2" length="1.5"')
edit("models_urdf/coupler_double.urdf", f'frame_b="BA_S2" length="{L}"', 'frame_b="BA_S2" length="1.5"')
edit("mjcf/coupler_single.xml", f'<connect name="link1" body1="link1" body2="platform_b" anchor="0 0 {L}"/>',
     '<connect name="link1" body1="link1" body2="platform_b" anchor="0 0 1.5"/>')
"""
MODELS_ENV = (("MBSUITE_MODELS_DIR", f"{DIR}/models"),)


def model_attempts() -> Iterator[Attempt]:
    """Model files: malformed XML copies, impossible loops, missing files, loaded through the documented API."""
    a = "model"
    mj = "from mbsuite.engines.mujoco_engine import load_model\n"
    pe = "from mbsuite.engines.pinocchio_engine import load_urdf, load_mjcf\n"
    # a shipped model file with the checks its model declares (the engine loaders alone name no model)
    mjf = "from mbsuite import load_model_file as load_model\n"
    pef = ("from mbsuite import load_model_file\n"
           "def load_urdf(p): return load_model_file(p, 'pinocchio')\n"
           "def load_mjcf(p): return load_model_file(p, 'pinocchio')\n")
    yield snip("fourbar-rocker-5m-mujoco", a, "iftomm four-bar with the rocker pivot at 5 m (loop cannot close): "
               "mbsuite.load_model_file", mjf + f"m = load_model('{DIR}/models/mjcf/iftomm_fourbar.xml')\n"
               "print(m.nq, m.neq)\n", culprit="iftomm_fourbar|closure", setup=ROCKER_5M)
    yield snip("fourbar-rocker-5m-pinocchio", a, "the same file through mbsuite.load_model_file(..., 'pinocchio')",
               pef + f"m = load_mjcf('{DIR}/models/mjcf/iftomm_fourbar.xml')\nprint(m.nq)\n",
               culprit="iftomm_fourbar|closure", setup=ROCKER_5M)
    yield snip("fourbar-rocker-5m-run", a, "the same file as the shipped model (MBSUITE_MODELS_DIR): "
               "mbsuite.run('iftomm/fourbar')", "import mbsuite\nr = mbsuite.run('iftomm/fourbar')\n"
               "print(r.summary())\n", culprit="closure", setup=ROCKER_5M, env=MODELS_ENV, timeout=120)
    yield cli("fourbar-rocker-5m-cli", a, "the same through `mbsuite run iftomm/fourbar --json`",
              "run iftomm/fourbar --json", culprit="closure", setup=ROCKER_5M, env=MODELS_ENV, timeout=120)
    yield cli("fourbar-rocker-5m-reference", a, "the same on the reference (Pinocchio) path",
              "run iftomm/fourbar --engine reference --json", culprit="closure", setup=ROCKER_5M, env=MODELS_ENV,
              timeout=120)
    yield snip("coupler-link-1.5-mujoco", a, "coupler_single.xml with link1's closure length 0.944 -> 1.5 m: "
               "mbsuite.load_model_file", mjf + f"m = load_model('{DIR}/models/mjcf/coupler_single.xml')\n"
               "print(m.neq)\n", culprit="link1|closure", setup=COUPLER_LINK)
    yield snip("coupler-link-1.5-urdf", a, "coupler_single.urdf with link1's closure length 1.5 m: "
               "mbsuite.load_model_file(..., 'pinocchio')",
               pef + f"m = load_urdf('{DIR}/models/models_urdf/coupler_single.urdf')\nprint(m.nq)\n",
               culprit="link1|closure", setup=COUPLER_LINK)
    for kind in ("single", "double"):
        yield snip(f"coupler-link-1.5-pincoupler-{kind}", a, f"the changed coupler_{kind}.urdf as the shipped model "
                   f"(MBSUITE_MODELS_DIR): coupler.pinocchio.PinCoupler.build({kind!r})",
                   "from mbsuite.models.coupler.pinocchio import PinCoupler\n"
                   f"pc = PinCoupler.build({kind!r})\nprint(pc.lengths)\n", culprit="link1|closure|length",
                   setup=COUPLER_LINK, env=MODELS_ENV)
    yield cli("coupler-link-1.5-dynamics", a, "the changed files: coupler dynamics (MuJoCo)",
              "coupler dynamics coupler --json", "either", culprit="link1|closure|length", setup=COUPLER_LINK,
              env=MODELS_ENV, timeout=120)
    src = (DIR + "/models/mjcf/iftomm_fourbar.xml", "iftomm_fourbar")
    bad_xml = {
        "truncated": "text = text[: len(text) // 2]",
        "unclosed-tag": "text = text.replace('</worldbody>', '')",
        "mass-abc": "text = text.replace('<geom ', '<geom mass=\"abc\" ', 1)",
        "mass-negative": "text = text.replace('<geom ', '<geom mass=\"-1\" ', 1)",
        "mass-nan": "text = text.replace('<geom ', '<geom mass=\"nan\" ', 1)",
        "unknown-element": "text = text.replace('<worldbody>', '<worldbody><teapot/>')",
        "empty": "text = ''",
        "garbage": "text = bytes(range(256)).decode('latin-1')",
        "latin1-comment": "text = text.replace('-->', ' caf\u00e9 -->', 1); enc = 'latin-1'",
        "entity-bomb": ("text = '<?xml version=\"1.0\"?><!DOCTYPE m [<!ENTITY a \"aaaaaaaaaa\">' + ''.join("
                        "f'<!ENTITY a{i} \"' + f'&a{i - 1 if i else \"\"};' * 10 + '\">' for i in range(1, 9))"
                        " + ']><mujoco model=\"&a8;\"/>'"),
        "connect-missing-body": "text = text.replace('body2=\"rocker\"', 'body2=\"nobody\"')",
        "timestep-negative": "text = text.replace('timestep=\"0.001\"', 'timestep=\"-1\"')",
    }
    for name, edit in bad_xml.items():
        setup = COPY_MODELS + f"""
f = pathlib.Path("{src[0]}")
text = f.read_text(); enc = 'utf-8'
{edit}
f.write_bytes(text.encode(enc, errors='replace'))
"""
        yield snip(f"xml-{name}-mujoco", a, f"iftomm_fourbar.xml {name}: mujoco_engine.load_model",
                   mj + f"m = load_model('{src[0]}')\nprint(m.nq)\n", culprit=src[1], setup=setup)
        if name in ("truncated", "garbage", "mass-nan", "empty", "entity-bomb", "timestep-negative"):
            yield cli(f"xml-{name}-run", a, f"iftomm_fourbar.xml {name} as the shipped model: run iftomm/fourbar",
                      "run iftomm/fourbar --json", culprit=src[1], setup=setup, env=MODELS_ENV)
        if name in ("truncated", "garbage", "mass-abc", "empty"):
            yield snip(f"xml-{name}-pinocchio", a, f"iftomm_fourbar.xml {name}: pinocchio_engine.load_mjcf",
                       pe + f"m = load_mjcf('{src[0]}')\nprint(m.nq)\n", culprit=src[1], setup=setup)
    urdf = DIR + "/models/models_urdf/pantograph.urdf"
    for name, edit in (("truncated", "text = text[: len(text) // 2]"),
                       ("mass-abc", "text = text.replace('<mass value=\"', '<mass value=\"abc', 1)"),
                       ("joint-no-parent", "text = text.replace('<parent link=', '<parent lnk=', 1)"),
                       ("empty", "text = ''")):
        setup = COPY_MODELS + f"""
f = pathlib.Path("{urdf}")
text = f.read_text()
{edit}
f.write_text(text)
"""
        yield snip(f"urdf-{name}", a, f"pantograph.urdf {name}: pinocchio_engine.load_urdf",
                   pe + f"m = load_urdf('{urdf}')\nprint(m.nq)\n", culprit="pantograph.urdf", setup=setup)
    drv = COPY_MODELS + f"""
f = pathlib.Path("{DIR}/models/mjcf/drive_step_up.xml")
f.write_text(f.read_text()[:200])
"""
    yield cli("drive-xml-truncated-run", a, "drive_step_up.xml truncated, drives scene on MuJoCo",
              f"run {DIR}/scene.toml --json", culprit="drive_step_up", setup=drv, env=MODELS_ENV,
              files=(("scene.toml", MODEL_SCENES["drives"].encode()),))
    yield snip("load-missing-file", a, "mujoco_engine.load_model of a missing file",
               mj + f"load_model('{DIR}/nope.xml')\n", culprit="nope.xml")
    yield snip("load-directory", a, "mujoco_engine.load_model of a directory", mj + f"load_model('{DIR}')\n",
               culprit=Path(DIR).name or "@DIR@")
    yield snip("load-xml-string-garbage", a, "load_model(from_string=True) of garbage",
               mj + "load_model('<mujoco><body', from_string=True)\n", culprit="string")
    yield snip("urdf-missing", a, "load_urdf of a missing file", pe + f"load_urdf('{DIR}/nope.urdf')\n",
               culprit="nope.urdf")
    yield snip("mjcf-of-urdf", a, "load_mjcf given a URDF file", pe + "import mbsuite.paths as P\n"
               "load_mjcf(P.models_root() / 'models_urdf' / 'pantograph.urdf')\n", "either",
               culprit="pantograph.urdf")
    yield cli("models-dir-missing", a, "MBSUITE_MODELS_DIR names a directory that does not exist",
              "run iftomm/fourbar --json", culprit="MBSUITE_MODELS_DIR|nowhere",
              env=(("MBSUITE_MODELS_DIR", f"{DIR}/nowhere"),))
    yield cli("models-dir-file-missing", a, "MBSUITE_MODELS_DIR without iftomm_fourbar.xml",
              "run iftomm/fourbar --json", culprit="iftomm_fourbar", env=MODELS_ENV,
              setup=COPY_MODELS + "(dst / 'mjcf' / 'iftomm_fourbar.xml').unlink()\n")


# ------------------------------------------------------------------------------------------------- command lines
def cli_attempts() -> Iterator[Attempt]:
    """Every command and flag: bad numbers, NaN, infinities, zero, negative, huge counts, bad outputs."""
    a = "cli"
    yield cli("no-command", a, "mbsuite without a command", (), culprit="command")
    yield cli("unknown-command", a, "an unknown command", "frobnicate", culprit="frobnicate")
    yield cli("version", a, "--version", "--version", "ok")
    yield cli("list-json", a, "list --json (control)", "list --json", "ok")
    yield cli("run-no-scene", a, "run without a scene", "run", culprit="scene")
    yield cli("run-unknown-scene", a, "run nosuch", "run nosuch --json", culprit="nosuch")
    yield cli("run-unknown-shipped-scene", a, "run pantograph/nosuch", "run pantograph/nosuch --json",
              culprit="nosuch")
    yield cli("run-engine-bad", a, "run --engine bullet", "run pantograph --engine bullet", culprit="--engine")
    yield cli("run-unknown-flag", a, "run --frobnicate", "run pantograph --frobnicate", culprit="--frobnicate")
    for v in ("0", "-1", "nan", "inf", "1e13", "abc", "0.5"):
        yield cli(f"run-max-steps={v}", a, f"run --max-steps {v}", ("run", "pantograph", "--max-steps", v),
                  culprit="max-steps|max_steps")
    for v in ("0", "-1", "nan", "inf", "abc"):
        yield cli(f"sweep-budget={v}", a, f"sweep --budget {v}",
                  ("sweep", "pantograph", "--vary", "input.frequency=2,4", "--budget", v), culprit="budget")
    yield cli("sweep-over-budget", a, "a sweep whose estimate exceeds --budget stops naming --yes",
              "sweep pantograph --vary input.frequency=2,4,6,8 --workers 1 --budget 0.001", culprit="--yes")
    yield cli("estimate-over-budget", a, "an error estimate whose companions exceed --budget stops before they run, "
              "naming --yes", "catenary catenary/en50318 --error-estimate --workers 1 --budget 0.001", culprit="--yes")
    yield cli("run-speed-without-a-speed", a, "--speed on a scene whose model has no speed",
              "run pantograph --speed 200", culprit="speed")
    yield cli("run-speed-and-set", a, "--speed and --set input.speed together",
              "run catenary/en50318 --speed 200 --set input.speed=100", culprit="--speed")
    yield cli("compare-one", a, "compare with a single summary", f"compare {DIR}", culprit="compare|two")
    yield cli("compare-missing", a, "compare a summary that does not exist", f"compare {DIR}/a {DIR}/b",
              culprit="a")
    yield cli("run-max-steps-guard", a, "run --max-steps 100 (the 10 000-step scene is refused)",
              "run pantograph --max-steps 100 --json", culprit="max_steps|max-steps")
    yield cli("run-out-file", a, "--out onto an existing file", f"run pantograph --out {DIR}/f.txt",
              culprit="--out", files=(("f.txt", b"x"),))
    yield cli("run-out-proc", a, "--out in /proc (cannot be created)", "run pantograph --out /proc/mbsuite_out",
              culprit="--out|/proc/mbsuite_out")
    yield cli("run-out-under-file", a, "--out below a regular file", "run pantograph --out /dev/null/x",
              culprit="--out|/dev/null/x")
    yield cli("run-out-json", a, "--out onto a file with --json (JSON error object)",
              f"run pantograph --json --out {DIR}/f.txt", culprit="--out", files=(("f.txt", b"x"),))
    yield cli("run-out-ok", a, "--out into a new directory (control)", f"run pantograph --out {DIR}/o", "ok")
    yield cli("run-wrong-hook-equilibrium", a, "equilibrium of a drives scene (no statics)",
              "equilibrium drives --json", culprit="equilibrium")
    yield cli("modes-coupler", a, "modes of the coupler (no linear modes)", "modes coupler --json", culprit="modes")
    yield cli("freqresp-iftomm", a, "freqresp of iftomm", "freqresp iftomm --json", culprit="freqresp")
    fr = ("freqresp", "pantograph", "--methods", "linear")
    for flag, vals in (("--f-min", ("nan", "inf", "0", "-1", "1e9", "abc")),
                       ("--f-max", ("nan", "-inf", "1e9", "0.5")),
                       ("--df", ("0", "-0.5", "nan", "1e-6", "inf"))):
        for v in vals:
            yield cli(f"freqresp{flag}={v}", a, f"freqresp {flag}={v}", (*fr, f"{flag}={v}"),
                      culprit=flag + ("|--f-min|frequencies" if flag != "--f-min" else "|frequencies"))
    for m in ("bogus", "", ",", "linear,bogus"):
        yield cli(f"freqresp-methods={m or 'empty'}", a, f"freqresp --methods {m!r}",
                  ("freqresp", "pantograph", "--methods", m), culprit="--methods")
    yield cli("freqresp-workers-negative", a, "freqresp --workers -1", (*fr, "--workers", "-1"), culprit="--workers")
    yield cli("freqresp-workers-huge", a, "freqresp --workers 100000 (should be refused or capped)",
              (*fr, "--f-max", "2", "--workers", "100000", "--json"), "either", culprit="--workers")
    yield cli("freqresp-workers-abc", a, "freqresp --workers abc", (*fr, "--workers", "abc"), culprit="--workers")
    yield cli("freqresp-dask-no-scheduler", a, "--executor dask without --scheduler",
              (*fr, "--executor", "dask"), culprit="scheduler")
    yield cli("freqresp-dask-bad-scheduler", a, "--executor dask --scheduler to a closed port (MuJoCo points)",
              ("freqresp", "pantograph", "--methods", "mujoco", "--f-max", "2", "--executor", "dask", "--scheduler",
               "tcp://127.0.0.1:9"), culprit="scheduler|127.0.0.1",
              timeout=90)
    yield cli("freqresp-executor-bogus", a, "--executor bogus", (*fr, "--executor", "bogus"), culprit="--executor")
    yield cli("freqresp-max-steps-nan", a, "freqresp --max-steps nan", (*fr, "--max-steps", "nan"),
              culprit="max-steps|max_steps")
    sw = ("sweep", "pantograph")
    for spec, cul, why in (("foo", "--vary", "no ="), ("input.frequency", "--vary", "no values"),
                           ("bogus.x=1", "--vary|bogus", "unknown section"), ("frequency=1,2", "--vary", "no section"),
                           ("input.frequency=", "--vary|frequency|sweep values", "empty values"),
                           ("input.frequency=1:0:1", "range|1:0:1", "stop below start"),
                           ("input.frequency=1:30:0", "range|1:30:0", "zero step"),
                           ("input.frequency=1:30:-1", "range|1:30:-1", "negative step"),
                           ("input.frequency=a:b:c", "a:b:c|range|--vary", "non-numeric range"),
                           ("input.frequency=1:nan:1", "nan|range", "NaN in a range"),
                           ("input.frequency=1:inf:1", "inf|range", "infinite range"),
                           ("input.frequency=nan,4", "frequency|sweep values", "NaN value"),
                           ("input.frequency=1:1e9:1", "points|--vary|max", "a billion points"),
                           ("input.frequency=1:1e300:1e-300", "points|--vary|max|range", "an absurd range"),
                           ("params.l1=-1,2", "l1", "a negative length among the values"),
                           ("params.nosuch=1", "nosuch", "unknown parameter"),
                           ("effects.cylinder=linear,bogus", "cylinder", "a bad effect value"),
                           ("solver.integrator=rk4,rk9", "integrator", "a bad integrator"),
                           ("solver.timestep=0", "timestep", "zero timestep"),
                           ("input.type=square", "square|type", "bad input type"),
                           ("outputs.signals=F1", "--vary|outputs", "outputs not variable"),
                           ("model.x=1", "--vary|model", "model as a section")):
        yield cli(f"sweep-vary-{why.replace(' ', '_')}", a, f"sweep --vary {spec} ({why})",
                  (*sw, "--vary", spec), culprit=cul)
    yield cli("sweep-no-vary", a, "sweep without --vary", "sweep pantograph", culprit="--vary")
    opt = ("optimise", "catenary/en50318", "--vary", "params.F0=100:140", "--maxiter", "1", "--popsize", "2")
    yield cli("optimise-band-unknown-system", a, "optimise --band XX (not a system of the model's band)",
              (*opt, "--band", "XX"), culprit="XX")
    yield cli("optimise-band-on-a-model-without", a, "optimise --band AC on the pantograph (it declares no band)",
              ("optimise", "pantograph/lab", "--vary", "params.ks=1e4:2e4", "--objective", "F1_amplitude",
               "--band", "AC"), culprit="band")
    yield cli("optimise-no-objective", a, "optimise of a model that declares no default objective, none given",
              ("optimise", "pantograph/lab", "--vary", "params.ks=1e4:2e4"), culprit="objective")
    yield cli("sweep-grid-product-huge", a, "two 2000-value axes (4 million points)",
              (*sw, "--vary", "input.frequency=1:2000:1", "--vary", "input.amplitude=1:2000:1"),
              culprit="points|--vary|max")
    yield cli("sweep-signals-unknown", a, "sweep --signals nosuch", (*sw, "--vary", "input.frequency=4",
                                                                     "--signals", "nosuch"), culprit="nosuch")
    yield cli("sweep-workers-negative", a, "sweep --workers -1", (*sw, "--vary", "input.frequency=4",
                                                                  "--workers", "-1"), culprit="--workers")
    yield cli("sweep-json-error", a, "sweep error under --json (JSON error object)",
              (*sw, "--vary", "params.l1=-1", "--json"), culprit="l1")
    for v in ("0", "-1", "1000000000"):
        yield cli(f"workprecision-repeats={v}", a, f"workprecision --repeats {v}",
                  ("workprecision", "pantograph", "--quick", "--repeats", v), culprit="--repeats", timeout=90)
    yield cli("workprecision-unknown", a, "workprecision of an unknown scene", "workprecision nosuch",
              culprit="nosuch")
    yield cli("hardcases-model-unknown", a, "hardcases --model nosuch", "hardcases --model nosuch",
              culprit="nosuch")
    yield cli("hardcases-name-unknown", a, "hardcases --name nosuch", "hardcases --name nosuch", culprit="nosuch")
    yield cli("list-out-file", a, "list --out onto a file", f"list --out {DIR}/f.txt", culprit="--out",
              files=(("f.txt", b"x"),))
    # coupler
    for flag, v in (("--gamma", "nan"), ("--gamma", "inf"), ("--gamma", "0"), ("--gamma", "1.0"),
                    ("--gamma", "-0.1"), ("--gamma", "0.7853981633974483"), ("--ey", "-1"), ("--ey", "1e9"),
                    ("--R", "0"), ("--R", "-1"), ("--R", "nan"), ("--phi-a", "inf"), ("--alpha-bx", "nan"),
                    ("--alpha-bz", "100")):
        cul = {"--ey": "--ey|e_y", "--R": "--R|R =|parameter R"}.get(flag, flag + "|" + flag[2:].replace("-", "_"))
        yield cli(f"coupler-jacobian{flag}={v}", a, f"coupler jacobian {flag} {v}", ("coupler", "jacobian", flag, v),
                  culprit=cul)
    yield cli("coupler-jacobian-engine-bogus", a, "coupler jacobian --engine bogus",
              "coupler jacobian --engine bogus", culprit="--engine")
    for v in ("2", "0", "-5", "1000000000", "3.5"):
        yield cli(f"coupler-fpp-n={v}", a, f"coupler fpp --n {v}", ("coupler", "fpp", "--n", v), culprit="--n",
                  timeout=60)
    yield cli("coupler-fpp-alpha-nan", a, "coupler fpp --alpha-bx nan", "coupler fpp --alpha-bx nan",
              culprit="--alpha-bx|alpha_bx")
    yield cli("coupler-fpp-alpha-huge", a, "coupler fpp --alpha-bx 3 (platform tilted past assembly)",
              "coupler fpp --alpha-bx 3 --json", culprit="alpha|assembl|reach")
    yield cli("coupler-dynamics-unknown", a, "coupler dynamics nosuch", "coupler dynamics nosuch",
              culprit="nosuch")
    yield cli("coupler-dynamics-wrong-model", a, "coupler dynamics of a pantograph scene",
              "coupler dynamics pantograph --json", culprit="pantograph")
    # drives
    srmin = ("drive", "design", "srmin")
    names = {"--P": "--P|P =|P must", "--wmin": "--wmin|w_min", "--wrip": "--wrip|w_rip", "--Jl": "--Jl|J_l"}
    for flag, v in (("--P", "0"), ("--P", "nan"), ("--wmin", "0"), ("--wrip", "-1"), ("--Jl", "inf")):
        args = {"--P": "100", "--wmin": "100", "--wrip": "10", "--Jl": "0.01", flag: v}
        yield cli(f"drive-srmin{flag}={v}", a, f"drive design srmin {flag} {v}",
                  (*srmin, *[x for k, val in args.items() for x in (k, val)]), culprit=names[flag])
    cad = ("drive", "design", "cadjs", "--P", "100", "--wmax", "400", "--vm", "100")
    for extra, cul, why in ((("--srmin", "abc"), "--srmin|abc", "non-numeric list"),
                            (("--srmin", ""), "--srmin|Sr_min", "empty list"),
                            (("--srmin", "nan"), "Sr_min|--srmin|srmin", "NaN"),
                            (("--srmin", "10", "--js", "0"), "J_s|--js", "zero spring inertia"),
                            (("--srmin", "10", "--js=-1e-5"), "J_s|--js", "negative spring inertia"),
                            (("--srmin", "10", "--wmin", "500"), "w_min|--wmin|wmax", "w_min above w_max"),
                            (("--srmin", "10", "--tau-c=-1"), "tau_c|--tau-c|clutch torque", "negative clutch torque")):
        yield cli(f"drive-cadjs-{why.replace(' ', '_')}", a, f"drive design cadjs {' '.join(extra)} ({why})",
                  (*cad, *extra), culprit=cul)
    for flag, v in (("--K", "0"), ("--xmax", "-1"), ("--fatigue", "2"), ("--E", "nan"), ("--sigma-uts", "0")):
        args = {"--K": "1.0", "--xmax": "3.0", flag: v}
        yield cli(f"drive-springsz{flag}={v}", a, f"drive design springsz {flag} {v}",
                  ("drive", "design", "springsz", *[x for k, val in args.items() for x in (k, val)]),
                  culprit={"--K": "--K|K =|K must", "--xmax": "--xmax|x_max", "--fatigue": "fatigue",
                           "--E": "--E|E =|E must", "--sigma-uts": "sigma_uts|--sigma-uts"}[flag])
    gains = ("drive", "design", "gains", "--Jl", "0.01", "--taul", "0.1", "--w0", "100")
    for extra, cul in ((("--ts", "0", "--btotal", "1e-4"), "--ts|t_s"), (("--ts", "0.002"), "--btotal|--P"),
                       (("--ts", "nan", "--btotal", "1e-4"), "--ts|t_s"),
                       (("--ts", "0.002", "--btotal", "-1"), "--btotal|B_total")):
        yield cli(f"drive-gains-{'_'.join(extra)}", a, f"drive design gains {' '.join(extra)}", (*gains, *extra),
                  culprit=cul)
    for v in ("0", "-1", "nan", "inf", "1e9"):
        yield cli(f"drive-run-duration={v}", a, f"drive run --duration {v}",
                  ("drive", "run", "drives/step_up_pwm", "--duration", v, "--json"), culprit="duration")
    yield cli("drive-run-wrong-model", a, "drive run of a pantograph scene", "drive run pantograph",
              culprit="pantograph")
    yield cli("drive-run-unknown", a, "drive run drives/nosuch", "drive run drives/nosuch", culprit="nosuch")
    for v in ("abc", "nan", "-1", "1e9"):
        yield cli(f"drive-efficiency-loads={v}", a, f"drive efficiency --loads {v}",
                  ("drive", "efficiency", "drives/step_up_efficiency", "--loads", v, "--duration", "1"),
                  culprit="loads|load", timeout=120)
    for v in ("0", "-1", "nan", "inf", "10", "1e-9"):
        yield cli(f"rotational-coupled-clutches-timestep={v}", a, f"rotational coupled-clutches --timestep {v}",
                  ("rotational", "coupled-clutches", "--timestep", v), culprit="timestep")
    # catenary
    for flag, v in (("--speed", "0"), ("--speed", "-1"), ("--speed", "nan"), ("--speed", "inf"),
                    ("--speed", "1e6"), ("--timestep", "0"), ("--timestep", "nan"), ("--timestep", "1"),
                    ("--element-length", "0"), ("--element-length", "-1"), ("--element-length", "nan"),
                    ("--element-length", "1e-5"), ("--element-length", "1e6")):
        cul = {"--speed": "speed", "--timestep": "timestep", "--element-length": "element_length|element-length"}
        yield cli(f"catenary{flag}={v}", a, f"catenary {flag} {v}", ("catenary", "--json", flag, v),
                  culprit=cul[flag], timeout=90)
    yield cli("catenary-wrong-model", a, "catenary of a pantograph scene", "catenary pantograph",
              culprit="pantograph")
    yield cli("catenary-mujoco-2mass", a, "catenary --engine mujoco with the 2-mass pantograph",
              "catenary --engine mujoco --json", culprit="mujoco|eppinger|reference2mass")
    train = ('model = "catenary"\n[effects]\ndroppers = "slack"\npantograph = "eppinger"\ncontact = "unilateral"\n'
             '[params]\nn_spans = 8\n[train]\npantographs = ["eppinger", "reference2mass"]\nspacings = [60.0]\n'
             '[input]\ntype = "passage"\nspeed = 250.0\n[solver]\nengine = "mujoco"\ntimestep = 1e-4\n')
    yield scene("catenary-train-eppinger-bad-pressure", a, "a train of an Eppinger and a 2-mass pantograph in the "
                "compiled loop, the Eppinger one's supply pressure negative", train + "[pantograph]\nparams = { Pg = "
                "-5.0 }\n", culprit="Pg", cmd=("catenary",))
    yield scene("catenary-train-eppinger-no-hold", a, "the same train, the Eppinger pantograph's supply pressure too "
                "low to hold the wire", train + "[pantograph]\nparams = { Pg = 1.0e5 }\n",
                culprit="Pg|hold|press", cmd=("catenary",), timeout=120)
    # Ctrl-C and closed pipes
    for what, argv, files in (
            ("sweep", f'"sweep", "pantograph", "--vary", "input.frequency=1:30:0.5", "--workers", "1", '
                      f'"--store", "{DIR}/s.jsonl"', ()),
            ("run", f'"run", "{DIR}/long.toml"',
             (("long.toml", PANTO.replace("duration = 2.0", "duration = 3000.0").encode()),))):
        yield snip(f"ctrl-c-{what}", a, f"SIGINT 5 s into a long {what}: exit 130 within 10 s, one line, no traceback",
                   f"""
            import signal, subprocess, sys, time
            p = subprocess.Popen([sys.executable, "-m", "mbsuite.cli", {argv}],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            time.sleep(5)
            t0 = time.monotonic()
            p.send_signal(signal.SIGINT)
            try:
                out, err = p.communicate(timeout=90)
            except subprocess.TimeoutExpired:
                p.kill()
                print("SIGINT not honoured within 90 s", file=sys.stderr)
                sys.exit(4)
            late = time.monotonic() - t0
            if "Traceback" in err:
                sys.stderr.write(err)
                sys.exit(1)
            assert p.returncode == 130, f"exit {{p.returncode}} after SIGINT, stderr {{err.strip()[-300:]!r}}"
            assert len(err.strip().splitlines()) == 1, f"{{len(err.strip().splitlines())}} stderr lines: {{err!r}}"
            if late > 10:
                print(f"SIGINT honoured only after {{late:.0f}} s (exit 130): {{err.strip()}}", file=sys.stderr)
                sys.exit(4)
            """, "ok", timeout=150, files=files)
    for argv in (("list",), ("hardcases",), ("run", "pantograph", "--json")):
        yield snip(f"closed-pipe-{argv[0]}", a, f"`mbsuite {' '.join(argv)}` into a closed pipe: quiet", f"""
            import subprocess, sys
            p = subprocess.Popen([sys.executable, "-m", "mbsuite.cli", *{argv!r}], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE)
            p.stdout.close()
            err = p.stderr.read().decode(errors="replace")
            p.wait(timeout=60)
            if "Traceback" in err:
                sys.stderr.write(err)
                sys.exit(1)
            assert not err.strip(), f"stderr not quiet (exit {{p.returncode}}): {{err.strip()[-300:]!r}}"
            assert p.returncode in (0, 141, -13), f"exit {{p.returncode}}"
            """, "ok")


# ----------------------------------------------------------------------------------------------------- numerics
def numerics_attempts() -> Iterator[Attempt]:
    """Legal but inaccurate settings, huge timesteps for every model, tiny timesteps that would hang."""
    a = "numerics"
    base = "\n".join(ln for ln in PANTO.splitlines() if not ln.startswith(("timestep", "integrator")))
    for integ, h, coulomb, why in (("discrete", "0.1", True, "discrete at 0.1 s"),
                                   ("discrete", "0.02", True, "discrete at 0.02 s"),
                                   ("rk4", "0.02", False, "rk4 at 0.02 s, coulomb off"),
                                   ("euler", "0.01", True, "euler at 0.01 s"),
                                   ("implicitfast", "0.05", True, "implicitfast at 0.05 s"),
                                   ("rk4", "0.5", True, "rk4 at 0.5 s")):
        text = with_lines(base, "solver", f'integrator = "{integ}"\ntimestep = {h}')
        if not coulomb:
            text = text.replace("coulomb = true", "coulomb = false")
        tag = why.replace(" ", "_").replace(",", "")
        yield scene(f"inaccurate-{tag}", a, f"pantograph {why}: health past its bounds", text, culprit="timestep")
        diverges = h in ("0.1", "0.05", "0.5")  # may leave the plausible range: a SolverError is then right
        yield scene(f"inaccurate-allowed-{tag}", a, f"pantograph {why} with --allow-inaccurate: kept, warned", text,
                    "either" if diverges else "ok", culprit="timestep", extra=("--json", "--allow-inaccurate"))
    yield scene("inaccurate-in-scene-allowed", a, "solver.allow_inaccurate = true in the scene",
                with_lines(base, "solver", 'integrator = "discrete"\ntimestep = 0.02\nallow_inaccurate = true'), "ok")
    yield cli("inaccurate-sweep", a, "sweep over an inaccurate timestep",
              ("sweep", f"{DIR}/scene.toml", "--vary", "solver.timestep=0.001,0.1", "--workers", "1"),
              culprit="timestep", files=(("scene.toml", PANTO.encode()),))
    yield cli("inaccurate-freqresp", a, "freqresp with MuJoCo at 0.05 s (scene)",
              ("freqresp", f"{DIR}/scene.toml", "--methods", "mujoco", "--f-min", "4", "--f-max", "5", "--df", "1"),
              culprit="timestep", files=(("scene.toml", with_lines(base, "solver", 'integrator = "rk4"\n'
                                                                    'timestep = 0.05').encode()),), timeout=120)
    for model, text in MODEL_SCENES.items():
        m = "\n".join(ln for ln in text.splitlines() if not ln.startswith(("timestep", "duration")))
        huge = with_lines(m, "solver", "timestep = 0.5\nduration = 2.0")
        yield scene(f"huge-timestep-{model}", a, f"{model} at timestep 0.5 s", huge, culprit="timestep", timeout=120)
        tiny = with_lines(m, "solver", "timestep = 1e-9\nduration = 2.0")
        yield scene(f"tiny-timestep-{model}", a, f"{model} at timestep 1e-9 s (2e9 steps: size guard)", tiny,
                    culprit="timestep|max_steps", timeout=60)
    ref = with_lines("\n".join(ln for ln in PANTO.splitlines() if not ln.startswith("engine")), "solver",
                     'engine = "reference"')
    yield scene("reference-max-step-tiny", a, "reference path with max_step = 1e-9 (2e9 internal steps)",
                with_lines(ref, "solver", "max_step = 1e-9"), culprit="max_step|max_steps", timeout=60)
    yield scene("reference-rtol-tight", a, "reference path at rtol = 1e-14, atol = 1e-14 (legal, slow?)",
                with_lines(ref, "solver", "rtol = 1e-14\natol = 1e-14"), "either", culprit="rtol", timeout=90)
    yield scene("reference-huge-timestep", a, "reference path with a 0.5 s output grid",
                with_lines(ref.replace("timestep = 1e-3", "timestep = 0.5"), None, ""), "either",
                culprit="timestep")
    yield scene("iftomm-sample-dt-tiny", a, "iftomm sample_dt 1e-12 (below the step)",
                with_lines(MODEL_SCENES["iftomm"], "solver", "sample_dt = 1e-12"), "either", culprit="sample_dt")
    yield scene("iftomm-solref-below-2h", a, "iftomm solref_timeconst 0.004 at timestep 0.01 (needs >= 2 h)",
                with_lines(with_lines(MODEL_SCENES["iftomm"], "solver", "timestep = 0.01"), "params",
                           "solref_timeconst = 0.004"), culprit="solref_timeconst|timestep")
    yield scene("pantograph-duration-1e5", a, "pantograph 1e5 s at 1 ms (1e8 steps: size guard)",
                PANTO.replace("duration = 2.0", "duration = 1e5"), culprit="max_steps|steps")
    yield scene("catenary-element-tiny", a, "catenary element_length 1e-4 m (6 million elements: size guard)",
                MODEL_SCENES["catenary"].replace("element_length = 0.5", "element_length = 1e-4"),
                culprit="element_length", timeout=90)
    yield scene("catenary-x-end-past-the-line", a, "catenary x_end 1e-6 beyond the 600 m line (not rounding)",
                with_lines(MODEL_SCENES["catenary"], "params", "x_end = 600.0006"), culprit="x_end")
    yield scene("catenary-window-end-past-the-run", a, "catenary window_end 1e-6 beyond x_end (not rounding)",
                with_lines(MODEL_SCENES["catenary"], "params", "x_end = 300.0\nwindow_start = 200.0\n"
                           "window_end = 300.0003"), culprit="window_end")
    yield scene("catenary-spans-huge", a, "catenary with 100 000 spans (memory)",
                with_lines(MODEL_SCENES["catenary"], "params", "n_spans = 100000"), culprit="n_spans", timeout=90)
    yield scene("coupler-omega-max", a, "coupler at omega = 1000 rad/s, timestep 5e-4 (fast spin)",
                MODEL_SCENES["coupler"].replace("omega = 12.566370614359172", "omega = 1000.0"), "either",
                culprit="timestep|omega", timeout=120)
    yield scene("pantograph-ks-huge", a, "pantograph ks = 1e12 N/m at rk4 1 ms (stiff: stability)",
                PANTO + "[params]\nks = 1e12\n", culprit="timestep|stability|ks")
    yield scene("drives-fs-huge-mujoco", a, "drives controller at 1 MHz with a 1e-4 s MuJoCo step",
                with_lines(MODEL_SCENES["drives"], "params", "fs = 1e6"), culprit="fs|timestep", timeout=120)
    yield scene("pantograph-tiny-stiffness", a, "pantograph ke = 1e-9 (elbow practically free)",
                PANTO + "[params]\nke = 1e-9\n", "either", culprit="ke|equilibrium")


# ----------------------------------------------------------------------------------------------------------- store
SWEEP_SCENE = PANTO.replace("duration = 2.0", "duration = 0.5").replace("t_settle = 1.0", "t_settle = 0.1")
MAKE_STORE = f"""
import base64, json, pathlib, pickle, subprocess, sys
scene = pathlib.Path("{DIR}/scene.toml")
store = pathlib.Path("{DIR}/s.jsonl")
r = subprocess.run([sys.executable, "-m", "mbsuite.cli", *@CMD@, "--store", str(store)], capture_output=True,
                   text=True)
assert r.returncode == 0, r.stderr
lines = store.read_bytes().splitlines(keepends=True)
assert lines, "the sweep wrote no store"

def records():
    for i, line in enumerate(lines):
        try:
            yield i, json.loads(line)
        except ValueError:
            pass

def result_of(rec):
    return rec.get("result", rec.get("body", {{}}).get("result")) if isinstance(rec, dict) else None

FORGED = ("max", "min", "mean", "contact_force_max", "contact_force_min")

def forge(obj):
    if isinstance(obj, dict):
        return {{k: (12345.678 if k in FORGED and isinstance(v, (int, float)) else forge(v))
                for k, v in obj.items()}}
    if isinstance(obj, list):
        return [forge(v) for v in obj]
    return obj

class Payload:
    def __reduce__(self):
        import os
        return (os.system, ("touch {DIR}/PWNED",))

def write(recs):
    out = []
    for i, line in enumerate(lines):
        out.append((json.dumps(recs[i]) + "\\n").encode() if i in recs else line)
    store.write_bytes(b"".join(out))
"""

FORGE = """
recs = {}
for i, rec in records():
    res = result_of(rec)
    if res is None:
        continue
    if "result" in rec:
        rec["result"] = forge(rec["result"])
    else:
        rec["body"]["result"] = forge(rec["body"]["result"])
    if "pickle" in rec:
        rec["pickle"] = base64.b64encode(pickle.dumps(forge(pickle.loads(base64.b64decode(rec["pickle"]))))).decode()
    recs[i] = rec
write(recs)
"""


def store_attempts() -> Iterator[Attempt]:
    """The sweep store: crafted pickle, forged record, truncated and non-UTF-8 lines, wrong paths, old format."""
    a = "store"
    files = (("scene.toml", SWEEP_SCENE.encode()),)
    cmd = ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4,5", "--workers", "1", "--store",
           f"{DIR}/s.jsonl", "--json")

    make = MAKE_STORE.replace("@CMD@", repr(["sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4,5",
                                             "--workers", "1"]))

    def st(name: str, what: str, setup: str, expect: str = "either", culprit: str | None = "s.jsonl",
           **kw) -> Attempt:
        return Attempt(name, a, what, expect, cmd, culprit=culprit, files=files, setup=make + setup, **kw)

    yield st("resume-control", "resume from an intact store (control)", "", "ok")
    yield st("crafted-pickle", "a record whose pickle runs os.system (must never execute)", """
recs = {}
for i, rec in records():
    if isinstance(rec, dict) and ("key" in rec or "body" in rec):
        rec["pickle"] = base64.b64encode(pickle.dumps(Payload())).decode()
        if isinstance(rec.get("body"), dict):
            rec["body"]["pickle"] = rec["pickle"]
        recs[i] = rec
write(recs)
""", forbid_files=("PWNED",))
    yield st("forged-record", "a record with its numbers changed to 12345.678 (checksum no longer matches)", FORGE,
             forbid_stdout=("12345.678",))
    yield st("truncated-line", "the last record cut in half (a killed writer)", """
store.write_bytes(b"".join(lines[:-1]) + lines[-1][: len(lines[-1]) // 2])
""", "ok")
    yield st("non-utf8-line", "a line of bytes that are not UTF-8", """
store.write_bytes(b"".join(lines) + b"\\xff\\xfe\\xfa not utf-8 \\x80\\x81\\n")
""")
    yield st("junk-line", "a line that is not JSON", """
store.write_bytes(b"".join(lines) + b"this is not json\\n")
""")
    yield st("json-not-object", "a line holding a JSON list", """
store.write_bytes(b"".join(lines) + b"[1, 2, 3]\\n")
""")
    yield st("json-depth-bomb", "a line nested 100 000 arrays deep (parser recursion)", """
store.write_bytes(b"".join(lines) + b"[" * 100000 + b"]" * 100000 + b"\\n")
""")
    yield st("huge-line", "a 50 MB line", """
store.write_bytes(b"".join(lines) + b'{"key": "' + b"a" * 50_000_000 + b'"}\\n')
""", timeout=90)
    yield st("old-pickle-format-payload", "the old pickle line format, its pickle running os.system", """
old = []
for i, rec in records():
    res = result_of(rec)
    if res is None:
        continue
    key = rec.get("key", rec.get("body", {}).get("key"))
    point = rec.get("point", rec.get("body", {}).get("point"))
    old.append(json.dumps({"key": key, "index": len(old), "point": point, "result": res,
                           "pickle": base64.b64encode(pickle.dumps(Payload())).decode()}) + "\\n")
store.write_text("".join(old))
""", forbid_files=("PWNED",))
    yield st("old-pickle-format-benign", "the old pickle line format with forged numbers in its pickle", """
old = []
for i, rec in records():
    res = result_of(rec)
    if res is None:
        continue
    key = rec.get("key", rec.get("body", {}).get("key"))
    point = rec.get("point", rec.get("body", {}).get("point"))
    old.append(json.dumps({"key": key, "index": len(old), "point": point, "result": forge(res),
                           "pickle": base64.b64encode(pickle.dumps(forge(res))).decode()}) + "\\n")
store.write_text("".join(old))
""", forbid_stdout=("12345.678",))
    yield Attempt("swapped-points", a, "two records with their results swapped: each point must keep its own "
                  "result", "either", snippet=f"""
import json, subprocess, sys
clean = json.load(open("{DIR}/clean.json"))
r = subprocess.run([sys.executable, "-m", "mbsuite.cli", *{cmd!r}], capture_output=True, text=True)
if r.returncode:
    sys.stderr.write(r.stderr)
    sys.exit(r.returncode)
got = json.loads(r.stdout)
assert got["points"] == clean["points"], "a resumed point carries another point's result"
print("same")
""", culprit="s.jsonl", files=files, setup=make + f"""
r = subprocess.run([sys.executable, "-m", "mbsuite.cli", *{cmd[:-3]!r}, "--json"], capture_output=True, text=True)
assert r.returncode == 0, r.stderr
open("{DIR}/clean.json", "w").write(r.stdout)
found = [(i, rec) for i, rec in records() if result_of(rec) is not None]
assert len(found) == 2, len(found)
(i, r1), (j, r2) = found
res1, res2 = result_of(r1), result_of(r2)
for rec, other in ((r1, res2), (r2, res1)):
    if "result" in rec:
        rec["result"] = other
    else:
        rec["body"]["result"] = other
p1, p2 = r1.get("pickle"), r2.get("pickle")
if p1 is not None:
    r1["pickle"], r2["pickle"] = p2, p1
write({{i: r1, j: r2}})
""")
    yield Attempt("store-directory", a, "--store names a directory", "error",
                  ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4", "--store", f"{DIR}/sd", "--json"),
                  culprit="sd|store", files=files, setup=f"import os; os.mkdir('{DIR}/sd')")
    yield Attempt("store-unwritable", a, "--store in /proc (cannot be created)", "error",
                  ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4", "--store", "/proc/mbs/s.jsonl"),
                  culprit="/proc/mbs|store", files=files)
    yield Attempt("store-under-file", a, "--store below a regular file", "error",
                  ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4", "--store", "/dev/null/s.jsonl"),
                  culprit="/dev/null|store", files=files)
    yield Attempt("store-is-scene", a, "--store names a TOML scene file (not a store: must not be appended to)",
                  "error", ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4", "--store",
                            f"{DIR}/scene.toml"), culprit="scene.toml|store", files=files)
    yield Attempt("store-empty-file", a, "--store names an empty file", "ok",
                  ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4", "--store", f"{DIR}/e.jsonl",
                   "--json"), files=(*files, ("e.jsonl", b"")))
    yield Attempt("store-binary-file", a, "--store names a binary file", "error",
                  ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4", "--store", f"{DIR}/b.bin"),
                  culprit="b.bin|store", files=(*files, ("b.bin", bytes(range(256)) * 64)))
    yield Attempt("store-fifo", a, "--store names a named pipe", "error",
                  ("sweep", f"{DIR}/scene.toml", "--vary", "input.frequency=4", "--store", f"{DIR}/p.jsonl"),
                  culprit="p.jsonl|store", files=files, setup=f"import os; os.mkfifo('{DIR}/p.jsonl')", timeout=30)
    fr = ["freqresp", f"{DIR}/scene.toml", "--methods", "mujoco", "--f-min", "4", "--f-max", "5", "--df", "1"]
    yield Attempt("freqresp-store-forged", a, "freqresp resumed from a store with forged numbers", "either",
                  (*fr, "--store", f"{DIR}/s.jsonl", "--json"), culprit="s.jsonl", files=files,
                  setup=MAKE_STORE.replace("@CMD@", repr(fr)) + FORGE, forbid_stdout=("12345.678",), timeout=120)


# --------------------------------------------------------------------------------------------------------- threads
THREADS = """
import threading
import numpy as np
import mbsuite

def arrays(res, scene):
    out = {"t": np.asarray(res.t)}
    names = list(getattr(res, "signals", None) or scene.outputs)
    for s in names:
        out[s] = np.asarray(res[s])
    return out

def run(ref):
    sc = mbsuite.load_scene(ref) if isinstance(ref, str) else ref
    return arrays(mbsuite.run(sc), sc)

def compare(refs):
    serial = [run(r) for r in refs]
    got, errs = [None] * len(refs), []
    def work(i, r):
        try:
            got[i] = run(r)
        except BaseException as exc:
            errs.append(exc)
    ts = [threading.Thread(target=work, args=(i, r)) for i, r in enumerate(refs)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    if errs:
        raise errs[0]
    for i, (a, b) in enumerate(zip(serial, got)):
        for k in a:
            assert a[k].shape == b[k].shape and np.array_equal(a[k], b[k], equal_nan=True), \\
                f"run {i} signal {k}: threaded differs from serial (max |diff| " \\
                f"{np.max(np.abs(a[k] - b[k])) if a[k].shape == b[k].shape else 'shape'})"
            assert np.all(np.isfinite(a[k])), f"run {i} signal {k}: non-finite values"
    print("identical", len(refs))
"""


def thread_attempts() -> Iterator[Attempt]:
    """Two (or more) models in threads through the Python API, compared with serial runs bit for bit."""
    a = "threads"
    def expr(ref: str, solver: dict, inp: dict | None = None) -> str:
        extra = f", input={inp!r}" if inp else ""
        return f"mbsuite.load_scene({ref!r}).replace(solver={solver!r}{extra})"

    pairs = {
        "pantograph+iftomm": ["pantograph", "iftomm/fourbar"],
        "pantograph+coupler": ["pantograph", "coupler"],
        "coupler+iftomm": ["coupler", "iftomm/bricard"],
        "pantograph+drives-mujoco": ["pantograph", "drives-mujoco"],
        "pantograph-x2-different-inputs": ["pantograph", "pantograph-8hz"],
        "four-models": ["pantograph", "iftomm/fourbar", "coupler", "drives-mujoco"],
        "pantograph-reference+mujoco": ["pantograph", "pantograph-reference"],
        "nonlinear-cylinder+unilateral": ["pantograph/nonlinear_cylinder", "pantograph/unilateral"],
    }
    short = {"duration": 3.0, "t_settle": 1.0}
    exprs = {
        "pantograph": expr("pantograph", short),
        "pantograph-8hz": expr("pantograph", short, {"frequency": 8.0}),
        "pantograph-reference": expr("pantograph", {"duration": 1.0, "t_settle": 0.5, "engine": "reference"}),
        "pantograph/nonlinear_cylinder": expr("pantograph/nonlinear_cylinder", short),
        "pantograph/unilateral": expr("pantograph/unilateral", short),
        "iftomm/fourbar": expr("iftomm/fourbar", {"duration": 3.0}),
        "iftomm/bricard": expr("iftomm/bricard", {"duration": 3.0}),
        "coupler": expr("coupler", {"duration": 1.0}),
        "drives-mujoco": expr("drives", {"duration": 1.0, "t_settle": 0.5, "engine": "mujoco"}),
    }
    for name, refs in pairs.items():
        code = THREADS + f"\ncompare([{', '.join(exprs[r] for r in refs)}])\n"
        yield snip(f"threads-{name}", a, f"{' and '.join(refs)} in threads vs serial: identical", code, "ok",
                   timeout=180)
    yield snip("threads-error-beside-run", a, "a failing scene in one thread beside a good run in another", THREADS
               + """
import mbsuite
good = mbsuite.load_scene("pantograph").replace(solver={"duration": 3.0, "t_settle": 1.0})
ref = run(good)
out, errs = {}, []
def bad():
    try:
        mbsuite.run(good.replace(solver={"integrator": "discrete", "timestep": 0.1}))
    except mbsuite.MbsuiteError as exc:
        errs.append(exc)
t1 = threading.Thread(target=bad)
t2 = threading.Thread(target=lambda: out.setdefault("g", run(good)))
t1.start(); t2.start(); t1.join(); t2.join()
assert errs, "the inaccurate run in the other thread was not refused"
for k in ref:
    assert np.array_equal(ref[k], out["g"][k]), f"good run's {k} changed by the failing thread"
print("ok")
""", "ok", timeout=180)
    yield snip("threads-sweep-executor", a, "run_sweep(executor='threads') vs serial on pantograph points", """
import numpy as np
import mbsuite
from mbsuite.analysis.sweep import run_sweep, scene_point
sc = mbsuite.load_scene("pantograph").replace(solver={"duration": 2.0, "t_settle": 1.0})
pts = [(sc.to_dict(), {"input": {"frequency": f}}) for f in (3.0, 4.25, 6.0, 8.0)]
a = run_sweep(scene_point, pts, workers=1)
b = run_sweep(scene_point, pts, workers=2, executor="threads")
assert a == b, "threaded sweep differs from the serial one"
print("identical")
""", "ok", timeout=180)


# --------------------------------------------------------------------------------- generated from the declarations
class Twice:
    """A value the TOML writer writes twice (a duplicate key)."""

    def __init__(self, value: object) -> None:
        self.value = value


def _toml_scalar(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_toml_scalar(x)}" for k, x in v.items()) + "}"
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_scalar(x) for x in v) + "]"
    raise TypeError(type(v))


def toml_text(data: dict, head: tuple[str, ...] = ()) -> str:
    """`data` as TOML: values first, then tables ([a.b]) and arrays of tables ([[a.b]])."""
    lines, later = [], []
    for k, v in data.items():
        name = json.dumps(k)
        if isinstance(v, dict) and v and all(not isinstance(x, Twice) for x in [v]):
            later.append((k, v, False))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            later.append((k, v, True))
        elif isinstance(v, Twice):
            lines += [f"{name} = {_toml_scalar(v.value)}"] * 2
        else:
            lines.append(f"{name} = {_toml_scalar(v)}")
    for k, v, many in later:
        path = ".".join(json.dumps(p) for p in (*head, k))
        for item in (v if many else [v]):
            lines.append(f"\n[[{path}]]" if many else f"\n[{path}]")
            lines.append(toml_text(item, (*head, k)))
    return "\n".join(lines)


#: how a user's file reaches a declared input file's loader: the command that reads it
FILE_COMMANDS = {"catenary.line_file": ("catenary",)}
#: declarations of one kind of a scene section: the scene tables that hold them
PART_OF = {"catenary.pantograph_lumped": lambda d: {"effects": {"pantograph": "lumped"}, "pantograph": {"params": d}},
           "catenary.pantograph_transfer": lambda d: {"effects": {"pantograph": "transfer"},
                                                      "pantograph": {"params": d}}}


def declared_attempts() -> Iterator[Attempt]:
    """For every key of every declared section (`mbsuite.scene_schema.sections`), written into a file as a user
    writes one (a line file, a scene with the section): missing where required, a wrong type, NaN, +-inf, below and
    above its range, huge, a fractional count, an unknown word, an empty or overlong list, a duplicate key. Each must
    be a clear error naming the key."""
    from mbsuite.limits import Limit
    from mbsuite.scene_schema import sections
    from mbsuite.schema import Section, bad_values, leaves

    a = "declared"
    wanted = {"text", "number", "bool", "nan", "inf", "-inf", "below", "above", "huge", "fraction", "unknown word",
              "empty", "item nan", "item below", "item text", "short row"}
    for name, sec in sections().items():
        model, key = name.split(".", 1)
        for path, decl, required in leaves(sec, sec.example, every_row=False):
            node, ok = sec.example, True
            for p in path[:-1]:
                try:
                    node = node[p]
                except (KeyError, IndexError, TypeError):
                    ok = False
            if not ok or isinstance(decl, Section) and path[-1] not in node:
                continue
            leaf = str(path[-1]) if not isinstance(path[-1], int) else str(path[-2])
            tag = ".".join(map(str, path))
            cases = [("missing", None)] if required else []
            cases += [(lab, v) for lab, v in bad_values(decl, node.get(path[-1])) if lab in wanted]
            if isinstance(decl, Limit) and path[-1] in node:
                cases.append(("duplicate", Twice(node[path[-1]])))
            for label, value in cases:
                data = copy.deepcopy(dict(sec.example))
                target = data
                for p in path[:-1]:
                    target = target[p]
                if label == "missing":
                    del target[path[-1]]
                else:
                    target[path[-1]] = value
                if name in FILE_COMMANDS:
                    text, cmd = toml_text(data), (*FILE_COMMANDS[name], f"{DIR}/input.toml", "--json")
                elif name in PART_OF:
                    text = f"model = {json.dumps(model)}\n" + toml_text(PART_OF[name](data))
                    cmd = ("run", f"{DIR}/input.toml", "--json")
                else:
                    text = f"model = {json.dumps(model)}\n" + toml_text({key: data})
                    cmd = ("run", f"{DIR}/input.toml", "--json")
                yield Attempt(f"declared-{name}-{tag}-{label.replace(' ', '-')}", a,
                              f"{name} {tag}: {label}", "error", cmd, culprit=leaf,
                              files=(("input.toml", text.encode()),))
    # every model's [params] and [input] keys and the [solver] settings, each in a scene file (the scene files of
    # the original corpus above try -inf, huge values, bools and the rest on a sample of them)
    from mbsuite.registry import models
    from mbsuite.settings import SOLVER_LIMITS, SOLVER_WORDS

    per_key = {"text", "nan", "inf", "below", "above", "fraction", "unknown word", "number"}
    for model, spec in models().items():
        keys = [("params", None, f.name, f.metadata["limit"]) for f in dataclasses.fields(spec.params_cls)
                if "limit" in f.metadata]
        keys += [("input", t, k, d) for t, keys_ in spec.inputs.items() for k, d in keys_.items()
                 if isinstance(d, Limit)]
        if model == "pantograph":  # one model's scene for the settings every model shares
            keys += [("solver", None, k, d) for k, d in {**SOLVER_LIMITS, **SOLVER_WORDS}.items()]
        for section, itype, key, decl in keys:
            good = decl.default if decl.has_default else None
            cases = [(lab, v) for lab, v in bad_values(decl) if lab in per_key]
            if good is not None and not isinstance(good, list | tuple):
                cases.append(("duplicate", Twice(good)))
            for label, value in cases:
                table = {key: value, **({"type": itype} if itype else {})}
                text = f"model = {json.dumps(model)}\n" + toml_text({section: table})
                yield Attempt(f"declared-{model}.{section}{'.' + itype if itype else ''}-{key}-"
                              f"{label.replace(' ', '-')}", a,
                              f"{model} {section}.{key}: {label}", "error", ("run", f"{DIR}/input.toml", "--json"),
                              culprit=key, files=(("input.toml", text.encode()),))


def corpus() -> list[Attempt]:
    """Every attempt, in a fixed order; names are unique."""
    out = [*scene_attempts(), *solver_value_attempts(), *model_attempts(), *cli_attempts(), *numerics_attempts(),
           *store_attempts(), *input_attempts(), *thread_attempts(), *declared_attempts()]
    names = [x.name for x in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise SystemExit(f"duplicate attempt names: {dup}")
    return out


# ---------------------------------------------------------------------------------------------------- the runner
@dataclass(frozen=True)
class Runner:
    """How attempts are run: interpreter, extra PYTHONPATH, timeout, memory limit, scratch root."""

    python: str
    pythonpath: str | None
    timeout: float
    scratch: Path
    memory: int = MEMORY_LIMIT

    def env(self, extra: tuple[tuple[str, str], ...], where: Path) -> dict[str, str]:
        env = dict(os.environ)
        if self.pythonpath:
            env["PYTHONPATH"] = os.pathsep.join(x for x in (self.pythonpath, env.get("PYTHONPATH")) if x)
        env.setdefault("MPLBACKEND", "Agg")
        env.pop("MBSUITE_DEBUG", None)
        for k, v in extra:
            env[k] = v.replace(DIR, str(where))
        return env

    def _limit(self) -> None:
        """In the attempt's process: the memory limit, and Ctrl-C's default disposition (a corpus started in the
        background inherits SIGINT ignored, which would make the Ctrl-C attempts meaningless)."""
        resource.setrlimit(resource.RLIMIT_AS, (self.memory, self.memory))
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    def _exec(self, cmd: list[str], env: dict[str, str], cwd: Path, timeout: float
              ) -> tuple[int | None, str, str, float]:
        t0 = time.monotonic()
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                             cwd=cwd, env=env, preexec_fn=self._limit, start_new_session=True)
        try:
            out, err = p.communicate(timeout=timeout)
            code: int | None = p.returncode
        except subprocess.TimeoutExpired:
            with contextlib.suppress(OSError):
                os.killpg(p.pid, signal.SIGKILL)
            out, err = p.communicate()
            code = None
        return code, out.decode(errors="replace"), err.decode(errors="replace"), time.monotonic() - t0

    def run(self, at: Attempt) -> Outcome:
        where = Path(tempfile.mkdtemp(prefix=at.name[:40].replace("/", "_") + ".", dir=self.scratch))

        def sub(text: str) -> str:
            return text.replace(DIR, str(where))

        env = self.env(at.env, where)
        for rel, data in at.files:
            (where / rel).parent.mkdir(parents=True, exist_ok=True)
            (where / rel).write_bytes(data.replace(DIR.encode(), str(where).encode()))
        command = [sub(x) for x in at.argv] if not at.snippet else sub(at.snippet)
        if at.setup:
            code, _, err, _ = self._exec([self.python, "-c", sub(at.setup)], env, where, 180)
            if code != 0:
                return self._outcome(at, command, "setup", code, 0.0, err, "setup failed")
        if at.snippet:
            (where / "harness.py").write_text(HARNESS)
            (where / "attempt.py").write_text(command)
            cmd = [self.python, str(where / "harness.py"), str(where / "attempt.py")]
        else:
            cmd = [self.python, "-m", "mbsuite.cli", *command]
        code, out, err, secs = self._exec(cmd, env, where, at.timeout or self.timeout)
        outcome, detail = classify(at, code, out, err, where)
        return self._outcome(at, command, outcome, code, secs, err, detail)

    @staticmethod
    def _outcome(at: Attempt, command: list[str] | str, outcome: str, code: int | None, secs: float, err: str,
                 detail: str) -> Outcome:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        return Outcome(at.name, at.area, at.what, at.expect, at.culprit, command, outcome, code, round(secs, 2),
                       lines[-1] if lines else "", detail, lines[-12:])


def bad_numbers(obj: object, path: str = "") -> list[str]:
    """Paths in a JSON document holding NaN/Infinity, or null where its siblings are numbers."""
    found: list[str] = []
    if isinstance(obj, float) and not math.isfinite(obj):
        found.append(path or "<root>")
    elif isinstance(obj, dict):
        nums = any(isinstance(v, int | float) and not isinstance(v, bool) for v in obj.values())
        for k, v in obj.items():
            if v is None and nums:
                found.append(f"{path}.{k}")
            found += bad_numbers(v, f"{path}.{k}")
    elif isinstance(obj, list):
        nums = any(isinstance(v, int | float) and not isinstance(v, bool) for v in obj)
        for i, v in enumerate(obj):
            if v is None and nums:
                found.append(f"{path}[{i}]")
            found += bad_numbers(v, f"{path}[{i}]")
    return found


def _json(text: str) -> object | None:
    try:
        return json.loads(text)
    except ValueError:
        return None


def classify(at: Attempt, code: int | None, out: str, err: str, where: Path) -> tuple[str, str]:
    """The outcome of one attempt and a short reason."""
    if code is None:
        return "hang", "timed out"
    for f in at.forbid_files:
        if (where / f).exists():
            return "silent", f"payload executed: {f} was created"
    for s in at.forbid_stdout:
        if s in out:
            return "silent", f"forged value {s!r} served in the output"
    if code == 4 and at.snippet:
        return "hang", "the snippet's command did not respond in time"
    if code < 0 or code not in (0, 1, 2, 3):
        return "crash", f"exit status {code}"
    if code == 1 or "Traceback (most recent call last)" in err:
        return "trace", "traceback"
    if code == 3:
        return "silent", "the snippet's own check failed"
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if code == 0:
        if at.expect == "error":
            return "silent", "exit 0 where an error was expected"
        doc = _json(out) if "--json" in at.argv else None
        bad = bad_numbers(doc) if doc is not None else []
        if bad:
            return "silent", f"NaN/null in the output at {', '.join(bad[:5])}"
        return "ok", ""
    # exit 2
    if at.expect == "ok":
        return "refused", "exit 2 where success was expected"
    prefix_ok = bool(lines) and (lines[0].startswith("mbsuite: error:") or
                                 (bool(at.snippet) and lines[0].split(":")[0].endswith("Error")))
    if len(lines) != 1 or not prefix_ok:
        return "unclear", f"{len(lines)} stderr lines" if len(lines) != 1 else "stderr line without the prefix"
    if "--json" in at.argv and not at.snippet:
        doc = _json(out)
        if not (isinstance(doc, dict) and isinstance(doc.get("error"), dict)):
            return "unclear", "no JSON error object on stdout"
    if at.culprit and not any(c.lower() in lines[0].lower() for c in at.culprit.replace(DIR, str(where)).split("|")):
        internal = " (an internal error: a defect path)" if "internal error" in lines[0] else ""
        return "culprit", f"message does not name {at.culprit!r}{internal}"
    return "clear", ""


# ------------------------------------------------------------------------------------------------------- reporting
def table(outcomes: list[Outcome]) -> str:
    """Counts by area (rows) and outcome (columns); at most 100 columns wide."""
    areas = [a for a in AREAS if any(o.area == a for o in outcomes)]
    cols = [c for c in OUTCOMES if c != "setup" or any(o.outcome == "setup" for o in outcomes)]
    head = f"{'area':<9}" + "".join(f"{c:>8}" for c in cols) + f"{'total':>7}{'pass':>7}"
    rows = [head, "-" * len(head)]
    for a in [*areas, "all"]:
        sel = [o for o in outcomes if a in ("all", o.area)]
        n = {c: sum(o.outcome == c for o in sel) for c in cols}
        passed = sum(o.outcome in PASSING for o in sel)
        if a == "all":
            rows.append("-" * len(head))
        rows.append(f"{a:<9}" + "".join(f"{n[c] or '.':>8}" for c in cols) + f"{len(sel):>7}{passed:>7}")
    return "\n".join(rows)


def show_command(o: Outcome) -> str:
    if isinstance(o.command, list):
        return "mbsuite " + " ".join(x if x and " " not in x else repr(x) for x in o.command)
    return "python: " + " | ".join(ln.strip() for ln in o.command.strip().splitlines()
                                   if ln.strip() and not ln.startswith(("import", "from")))[:300]


def failures(outcomes: list[Outcome]) -> str:
    out = []
    for o in outcomes:
        if o.outcome in PASSING:
            continue
        out.append(f"- [{o.area}] {o.name} ({o.what}): {o.outcome.upper()}"
                   f"{' - ' + o.detail if o.detail else ''}\n    {show_command(o)}\n"
                   f"    stderr: {o.last_line[:400] or '(empty)'}")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    default_python = Path(__file__).resolve().parents[1] / ".venv" / "bin" / "python"
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--area", help=f"comma list of areas ({', '.join(AREAS)}); default all")
    ap.add_argument("--name", action="append", help="only attempts whose name contains this (repeatable)")
    ap.add_argument("--workers", type=int, default=2, help="attempts run in parallel (default 2)")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per attempt unless it states its own")
    ap.add_argument("--python", default=str(default_python) if default_python.exists() else sys.executable,
                    help="interpreter that runs mbsuite (default: the repository's .venv)")
    ap.add_argument("--pythonpath", help="prepended to PYTHONPATH (run the corpus against another checkout)")
    ap.add_argument("--json-out", metavar="PATH", help="write every outcome as JSON")
    ap.add_argument("--list", action="store_true", help="list the attempts and exit")
    args = ap.parse_args(argv)
    attempts = corpus()
    if args.area:
        wanted = {x.strip() for x in args.area.split(",") if x.strip()}
        bad = sorted(wanted - set(AREAS))
        if bad:
            ap.error(f"unknown area(s) {bad}; valid: {', '.join(AREAS)}")
        attempts = [x for x in attempts if x.area in wanted]
    if args.name:
        attempts = [x for x in attempts if any(n in x.name for n in args.name)]
    if args.list:
        for x in attempts:
            print(f"{x.area:<9} {x.expect:<6} {x.name}: {x.what}")
        print(f"{len(attempts)} attempts")
        return 0
    if args.workers < 1:
        ap.error("--workers must be >= 1")
    scratch = Path(tempfile.mkdtemp(prefix="mbsuite_corpus."))
    runner = Runner(args.python, args.pythonpath, args.timeout, scratch)
    probe = subprocess.run([args.python, "-c", "import mbsuite, mbsuite.native as n; n.load(); "
                                               "print(mbsuite.__file__)"],
                           capture_output=True, text=True, env=runner.env((), scratch))
    started = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    print(f"mbsuite under test: {probe.stdout.strip() or probe.stderr.strip()[-300:]} ({started}; "
          f"{len(attempts)} attempts, {args.workers} workers)", flush=True)
    outcomes: list[Outcome] = []
    t0 = time.monotonic()
    with ThreadPoolExecutor(max_workers=args.workers) as pool:
        futs = {pool.submit(runner.run, x): x for x in attempts}
        for i, fut in enumerate(as_completed(futs), 1):
            try:
                o = fut.result()
            except Exception as exc:  # noqa: BLE001 - a fault of this script: record it, keep going
                x = futs[fut]
                o = Outcome(x.name, x.area, x.what, x.expect, x.culprit, x.command(), "setup", None, 0.0,
                            f"corpus runner failed: {type(exc).__name__}: {exc}")
            outcomes.append(o)
            print(f"[{i}/{len(attempts)}] {o.outcome:<8} {o.seconds:6.1f}s {o.area}/{o.name}", file=sys.stderr,
                  flush=True)
    order = {x.name: i for i, x in enumerate(attempts)}
    outcomes.sort(key=lambda o: order[o.name])
    print(table(outcomes))
    print(f"\nwall time {time.monotonic() - t0:.0f} s\n\nnot passing:\n{failures(outcomes) or '(none)'}")
    if args.json_out:
        Path(args.json_out).write_text(json.dumps({
            "mbsuite": probe.stdout.strip(), "started": started, "python": args.python,
            "pythonpath": args.pythonpath, "attempts": len(outcomes),
            "counts": {a: {c: sum(o.area == a and o.outcome == c for o in outcomes) for c in OUTCOMES}
                       for a in AREAS},
            "outcomes": [asdict(o) for o in outcomes]}, indent=1))
    shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
