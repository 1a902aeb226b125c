"""Figures whose words a reader can read: titles show the loads in kN and kN m, not a
raw ``Loads(Fx=0.0, ...)``, and no label, title or legend runs past the figure's edge."""
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")

from slewing_model import Loads                                      # noqa: E402
from slewing_model.study.figures import overview                     # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _saved_figure(monkeypatch, draw):
    """The figure ``draw()`` saves, and the texts of it that do not fit in what is saved (looked
    at as it is saved, before the figure is closed)."""
    import matplotlib.figure

    seen = []
    original = matplotlib.figure.Figure.savefig

    def spy(fig, *a, **k):
        result = original(fig, *a, **k)
        seen.append((fig, _texts_outside(fig, k.get("dpi", fig.dpi), k.get("bbox_inches") == "tight")))
        return result

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    draw()
    return seen[-1]


def _texts_outside(fig, dpi: float, saved_with_tight_box: bool) -> list[str]:
    """The visible texts (tick labels, axis labels, titles, legends) that do not fit in the figure
    (or, for a figure saved with ``bbox_inches="tight"``, in the box that is saved), drawn at the
    resolution it was saved with (text widths do not scale exactly with it)."""
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox

    fig.set_dpi(dpi)
    fig.canvas.draw()                                                # lays out as savefig did
    renderer = fig.canvas.get_renderer()
    frame = fig.get_tightbbox(renderer).transformed(fig.dpi_scale_trans) if saved_with_tight_box else fig.bbox
    frame = Bbox.from_extents(frame.x0 - 1, frame.y0 - 1, frame.x1 + 1, frame.y1 + 1)
    texts = list(fig.texts) + ([fig._suptitle] if fig._suptitle is not None else [])
    for ax in fig.axes:              # the tick labels drawn (those of ticks within the view), titles, labels
        for axis in (ax.xaxis, ax.yaxis) if ax.axison else ():      # an axes turned off draws no ticks
            texts += [label for tick in axis._update_ticks() for label in (tick.label1, tick.label2)]
        texts += list(ax.texts)
        texts += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label]
        if ax.get_legend() is not None:
            texts += ax.get_legend().get_texts()
    outside = []
    for text in texts:
        if isinstance(text, Text) and text.get_visible() and text.get_text().strip():
            box = text.get_window_extent(renderer)
            if not (frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1):
                outside.append(text.get_text())
    return outside


def test_loads_read_in_kn_and_knm():
    assert str(Loads(Fz=800e3, My=1.2e6)) == "Fz = 800 kN, My = 1200 kN m"
    assert str(Loads(Fx=-12.5, Mx=250.0)) == "Fx = -0.0125 kN, Mx = 0.25 kN m"
    assert str(Loads()) == "no load"
    assert "Loads(" not in f"{Loads(Fz=1e5)}"


def test_plot_command_title_states_the_loads_with_units(tmp_path, monkeypatch):
    from slewing_model.cli import main

    out = tmp_path / "p.png"
    fig, _ = _saved_figure(monkeypatch, lambda: main(["plot", str(ROOT / "examples/bearings/table3.toml"),
                                                      "--fz", "8e4", "--my", "1.5e4", "-o", str(out)]))
    title = fig._suptitle.get_text()
    assert "Fz = 80 kN, My = 15 kN m" in title and "Loads(" not in title, title
    assert out.is_file()


def _row(load, variant, k):
    value = 1e3 * (1 + k)
    return {"status": "ok", "name": f"{load} | {variant}", "ring_model": "rigid" if k % 2 else "flexible",
            "preload_um": str(float(10 * (k % 5))), "friction_coefficient": "0.1", "bearing": "pitch_bearing.toml",
            "load": load, "friction_torque_mean": str(value), "friction_torque_p99": str(1.5 * value),
            "friction_torque_max": str(2 * value), "max_ball_load": str(50 * value),
            "min_static_safety_factor": str(4.0), "friction_energy": str(10 * value)}


@pytest.mark.parametrize("cases", [16, 120])      # bars per case, and box plots per group beyond 40 cases
def test_overview_keeps_long_case_names_inside_the_figure(tmp_path, monkeypatch, cases):
    loads = ["OC3-Hywind 12 m/s blade 1", "FASTv8 land 12 m/s blade 1 (turbulent, 60 s)"]
    rows = [_row(loads[k % 2], f"pitch_bearing, {'rigid' if k % 2 else 'flexible'}, preload {10 * (k % 5)} um, "
                               f"mu 0.1, errors seed {k}", k) for k in range(cases)]
    fig, outside = _saved_figure(monkeypatch, lambda: overview(str(tmp_path / "o.png"), rows))
    longest = max((t.get_text() for t in fig.axes[0].get_yticklabels()), key=len)
    assert len(longest) > 40                                         # the labels are long ones
    assert outside == []


def test_torque_against_psi_keeps_its_titles_inside_the_figure(tmp_path, monkeypatch):
    """examples/friction_study.py's torque_vs_psi.png, drawn from a stand-in torque (its layout
    only: the friction computation is the example's own)."""
    sys.path.insert(0, str(ROOT / "examples"))
    import friction_study

    monkeypatch.setattr(friction_study, "torque_ripple",
                        lambda bearing, loads, psi, **kw: 100.0 + 20.0 * np.sin(3 * np.asarray(psi)))
    monkeypatch.setattr(friction_study, "flexible_superelement", lambda bearing: (object(), ""))
    fig, outside = _saved_figure(monkeypatch, lambda: friction_study.psi_figure(tmp_path, True))
    assert outside == []
    assert friction_study.ERRORS_TEXT in fig._suptitle.get_text()   # the error amplitudes still stated


def _life_case(folder, damage_map, duration=100.0, dg03_h=float("inf")):
    """A case folder as a study writes it (raceway_damage.csv, life_cycles.csv, life_summary.json)."""
    import json

    folder.mkdir(parents=True)
    angle = (np.arange(damage_map.shape[1]) + 0.5) * 360.0 / damage_map.shape[1]
    np.savetxt(folder / "raceway_damage.csv", np.column_stack([angle, damage_map.T]), delimiter=",",
               header="angle_deg,contact1,contact2,contact3,contact4", comments="")
    track = damage_map.sum(axis=1)
    cycles = np.column_stack([np.full(3, 1.0), np.full(3, 0.5), [0.5, 3.0, 900.0]] + [np.full(3, t / 3) for t in track])
    np.savetxt(folder / "life_cycles.csv", cycles, delimiter=",", comments="",
               header="swing_rad,count,travel_ratio,damage_1,damage_2,damage_3,damage_4")
    summary = {"duration_s": duration, "track_damage": list(track), "life_dg03_L10_h": dg03_h,
               "life_worst_track": int(np.argmax(track)) + 1, "micro_swing_rad": 1e-5}
    (folder / "life_summary.json").write_text(json.dumps(summary))
    return str(folder)


def _life_groups(tmp_path, count):
    """``count`` bearing variants with long names and damage maps decades apart (one far above the
    rest); DG03 sees no damage in half of them."""
    rng = np.random.default_rng(3)
    shape = 1.0 + 0.5 * np.sin(np.radians(np.arange(0.5, 360, 1.0)))[None, :] * np.ones((4, 1))
    groups = {}
    for k in range(count):
        scale = 1e3 if k == count - 1 else 10 ** rng.uniform(-3, 0)
        label = f"pitch_bearing_nrel5mw, flexible, preload {10 * (k % 5)} um, mu 0.1, errors seed {k}"
        groups[label] = [_life_case(tmp_path / f"c{k}", 1e-9 * scale * shape, dg03_h=float("inf") if k % 2 else 1e6)]
    return groups


def _overlapping_texts(fig) -> list[tuple[str, str]]:
    """Pairs (text, what it runs into) of a title, a text or a legend drawn over another axes'
    frame or over another of these texts (a title clipped by the next panel, a legend over a text)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()                      # the figure was closed once saved: lay it out again
    renderer = fig.canvas.get_renderer()
    items = []
    for ax in fig.axes:
        for t in [ax.title, ax._left_title, ax._right_title] + list(ax.texts):
            if t.get_visible() and t.get_text().strip():
                items.append((ax, t.get_window_extent(renderer), t.get_text()))
        if ax.get_legend() is not None:
            items.append((ax, ax.get_legend().get_window_extent(renderer), "legend"))
    shrink = lambda b: b.expanded(1, 1).__class__.from_extents(b.x0 + 1, b.y0 + 1, b.x1 - 1, b.y1 - 1)  # noqa: E731
    found = []
    for i, (ax, box, text) in enumerate(items):
        for other in fig.axes:
            if other is not ax and other.axison and shrink(box).overlaps(other.bbox):
                found.append((text, f"axes {other.get_title(loc='left') or other.get_title()}"))
        for _, box2, text2 in items[i + 1:]:
            if shrink(box).overlaps(shrink(box2)):
                found.append((text, text2))
    return found


@pytest.mark.parametrize("count", [1, 6, 200])     # one duty; a line per variant; median and band beyond six
def test_life_figure_keeps_its_texts_apart_and_its_median_in_view(tmp_path, monkeypatch, count):
    from slewing_model.study.figures import life_figure

    groups = _life_groups(tmp_path, count)
    draw = lambda: life_figure(str(tmp_path / "life.png"), groups if count > 1 else next(iter(groups.values())))  # noqa: E731
    fig, outside = _saved_figure(monkeypatch, draw)
    assert outside == []
    assert _overlapping_texts(fig) == []
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert not any("median inf" in t or "median nan" in t for t in texts), texts
    if count > 6:    # the median of the variants is drawn well above the axis' foot, not flattened by the largest
        for ax in fig.axes[:4]:
            median = next(a for a in ax.patches + ax.lines if a.get_label() == "median")
            path = median.get_path().transformed(median.get_transform())
            y = path.vertices[:, 1]
            y = y[np.isfinite(y)]
            height = (np.median(y) - ax.bbox.y0) / ax.bbox.height
            assert 0.2 < height <= 1.0, (ax.get_title(loc="left"), height)
