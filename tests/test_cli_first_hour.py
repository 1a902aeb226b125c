"""A new user's first hour with the ``slewing`` command: no silent wrong answers,
no nonsense figures, a clean stop on Ctrl-C."""
import json
import math
import subprocess
import sys
from pathlib import Path

from slewing_model import Loads, load_bearing, solve

ROOT = Path(__file__).resolve().parents[1]
SLEWING = str(Path(sys.executable).with_name("slewing"))


def _run(*args, **kw):
    return subprocess.run([SLEWING, *args], capture_output=True, text=True, cwd=kw.pop("cwd", ROOT),
                          timeout=kw.pop("timeout", 300), **kw)


# ---- static safety factor ------------------------------------------------------------------------

def test_overload_warns_on_stderr_but_still_answers():
    # 30 MN on table1's 100 balls: about 420 kN a ball at 45 deg, far beyond the ISO 76 4200 MPa
    # (the paper's Table 1 bearing carries a few MN); a warning, not an error: rc 0 and the table
    out = _run("solve", "examples/bearings/table1.toml", "--fz", "3e7")
    assert out.returncode == 0, out.stderr
    assert "warning: static safety factor" in out.stderr and "below 1" in out.stderr
    assert "4200 MPa" in out.stderr
    assert "friction torque" in out.stdout


def test_ordinary_load_gives_no_warning():
    out = _run("solve", "examples/bearings/table3.toml", "--fz", "5e4")
    assert out.returncode == 0 and "warning" not in out.stderr, out.stderr


def test_json_lists_the_warnings():
    out = _run("solve", "examples/bearings/table1.toml", "--fz", "3e7", "--json")
    data = json.loads(out.stdout)
    assert any("static safety factor" in w for w in data["warnings"])
    assert json.loads(_run("solve", "examples/bearings/table3.toml", "--fz", "5e4", "--json").stdout)["warnings"] == []


def test_unloaded_bearing_reports_no_safety_factor_and_no_four_point_balls():
    # no load, no preload: no ball carries anything, so there is no finite safety factor and no
    # ball is in four-point contact (round-off used to give 2.3e19 and "67 balls")
    out = _run("solve", "examples/bearings/table3.toml")
    assert out.returncode == 0, out.stderr
    line = next(l for l in out.stdout.splitlines() if "static safety factor" in l)
    assert "e+" not in line and "(unloaded)" in line and "0 balls in four-point contact" in line
    data = json.loads(_run("solve", "examples/bearings/table3.toml", "--json").stdout)
    assert data["static_safety_factor"] is None and data["balls_in_four_point_contact"] == 0


def test_library_warnings_for_the_fmu():
    # the check the FMU's log calls (LoadDistribution.warnings): the same sentences as the CLI
    table1 = load_bearing(ROOT / "examples/bearings/table1.toml")
    heavy = solve(table1, Loads(Fz=3e7))
    assert heavy.static_safety_factor < 1 and heavy.warnings()[0].startswith("static safety factor")
    assert solve(table1, Loads(Fz=1e5)).warnings() == []
    idle = solve(load_bearing(ROOT / "examples/bearings/table3.toml"), Loads())
    assert idle.static_safety_factor == math.inf and idle.warnings() == []


# ---- version, help, one mesh default, a prebuilt superelement -------------------------------------

def test_version():
    import slewing_model

    out = _run("--version")
    assert out.returncode == 0 and out.stdout.strip() == f"slewing {slewing_model.__version__}"


def test_help_shows_the_defaults():
    solve_help = _run("solve", "-h").stdout.split("options:", 1)[1]
    for option, default in (("--model", "rigid"), ("--mesh", "coarse"), ("--bc", "free"), ("--fz", "0.0")):
        block = solve_help.split(option + " ", 1)[1].split("\n  -", 1)[0]
        assert f"(default: {default})" in " ".join(block.split()), (option, block)
    assert "(default: the friction model's)" in " ".join(solve_help.split())      # --mu: none in numbers
    assert "(default: free)" in " ".join(_run("superelement", "-h").stdout.split())


def test_one_mesh_default_across_commands():
    from slewing_model.study.definition import SIMULATION_DEFAULTS

    defaults = set()
    for command in ("solve", "plot", "superelement"):
        text = " ".join(_run(command, "-h").stdout.split("options:", 1)[1].split())
        mesh = text.split("--mesh {coarse,fine,finer} ", 1)[1]
        defaults.add(mesh.split("(default: ", 1)[1].split(")", 1)[0])
    assert defaults == {SIMULATION_DEFAULTS["mesh"]}


def test_solve_and_plot_use_a_prebuilt_superelement(tmp_path):
    import os

    env = dict(os.environ, SLEWING_CACHE_DIR=str(tmp_path / "cache"))
    npz = tmp_path / "table3.npz"
    built = _run("superelement", "examples/bearings/table3.toml", "--bc", "clamped", "--quiet", "-o", str(npz), env=env)
    assert built.returncode == 0, built.stderr
    with_file = json.loads(_run("solve", "examples/bearings/table3.toml", "--fz", "3e4", "--superelement", str(npz),
                                "--json", env=env).stdout)
    built_here = json.loads(_run("solve", "examples/bearings/table3.toml", "--fz", "3e4", "--model", "flexible",
                                 "--bc", "clamped", "--json", env=env).stdout)
    rigid = json.loads(_run("solve", "examples/bearings/table3.toml", "--fz", "3e4", "--json").stdout)
    assert with_file["model"] == "flexible"
    assert with_file["displacement"]["z"] == built_here["displacement"]["z"] > rigid["displacement"]["z"]
    png = tmp_path / "p.png"
    plotted = _run("plot", "examples/bearings/table3.toml", "--fz", "3e4", "--superelement", str(npz), "-o", str(png),
                   env=env)
    assert plotted.returncode == 0 and png.exists(), plotted.stderr
    # a superelement of another bearing is refused, naming what differs
    other = _run("solve", "examples/bearings/table1.toml", "--superelement", str(npz), env=env)
    assert other.returncode == 2 and "error" in other.stderr and "Traceback" not in other.stderr
