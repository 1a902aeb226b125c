"""The OpenFAST / FAST output reader: round trips in every format, the shipped real
files against the statistics of another reader, and clear errors."""
import math
from pathlib import Path

import numpy as np
import pytest

from openfast_files import packing, write_binary, write_text
from slewing_model.loads.openfast import MissingChannelError, OpenFastFormatError, OutputFile, read_output

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "openfast"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"the real OpenFAST files are not here: {DATA} is absent")

V8 = "NREL5MW_Land_FASTv8_CertTest18_turb12mps_60s.outb"
V7 = "NREL5MW_Land_FASTv7_CertTest18_turb12mps_60s.outb"
TEST = "pCrunch_Test{}.NREL5MW_OC3Hywind_FASTv7_600s.outb"
IEA = "pCrunch_step_0.IEA15MW_floating_OpenFAST_stepwind_100s.outb"
WINDPACT = "WindPACT1.5MW_FASTv8_CertTest13_turb_40s.out"

NAMES = ["Time", "BldPitch1", "RootFzb1", "RootMyb1", "YawBrFzp", "Constant"]
UNITS = ["s", "deg", "kN", "kN·m", "kN", "-"]


def _run(n=401, seed=3):
    """A smooth synthetic record: a mean, a slow wave and noise per channel, one constant channel."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 20.0, n)
    values = np.column_stack([
        4.0 + 3.0 * np.sin(0.3 * t),                                  # deg
        600.0 + 120.0 * np.sin(1.26 * t) + rng.normal(0, 5, n),       # kN
        8000.0 + 1500.0 * np.sin(0.7 * t) + rng.normal(0, 50, n),     # kN m
        -3477.0 + 20.0 * rng.standard_normal(n),                      # kN, |mean| >> range
        np.full(n, 2.5),                                              # a constant channel
    ])
    return t, values


# --- round trips --------------------------------------------------------------------------------

@pytest.mark.parametrize("file_id", [1, 2, 4])
def test_packed_binary_round_trip_within_one_quantisation_level(tmp_path, file_id):
    t, values = _run()
    path = write_binary(tmp_path / f"run{file_id}.outb", t, NAMES, UNITS, values, file_id)
    out = read_output(path)
    assert out.file_id == file_id and out.names == NAMES
    assert [out.units[n] for n in NAMES] == UNITS                      # parentheses stripped, Latin-1 decoded
    # each value was rounded to the nearest of 65536 levels over the channel's range: error <= half a level;
    # the float32 offset is itself rounded, by half its ulp, which the slope scales back (this dominates for
    # the constant channel, whose "range" is sqrt(eps32)). Bound: one level plus one ulp of the offset.
    slope, offset = packing(values)
    level = 1.0 / slope.astype(float)
    bound = level + np.spacing(np.abs(offset)).astype(float) / slope
    error = np.abs(np.column_stack([out.channels[n] for n in NAMES[1:]]) - values)
    assert np.all(error <= bound), (error.max(axis=0), bound)
    assert np.all(error.max(axis=0)[:4] > 0.05 * level[:4])           # really quantised (not a float copy)
    if file_id == 1:                                                    # time packed in int32 over its range
        assert np.max(np.abs(out.time - t)) <= (t[-1] - t[0]) / 2**32 * 1.01
    else:                                                               # TimeOut1 + i TimeIncr
        assert np.allclose(out.time, t, rtol=0, atol=1e-12)


def test_fileid_1_keeps_a_variable_time_step(tmp_path):
    t = np.cumsum(np.r_[0.0, np.full(50, 0.01), np.full(50, 0.05)])   # the step changes half way
    values = np.column_stack([np.sin(t), np.cos(t)])
    out = read_output(write_binary(tmp_path / "var.outb", t, ["Time", "A", "B"], ["s", "-", "-"], values, 1))
    assert np.max(np.abs(out.time - t)) <= (t[-1] - t[0]) / 2**32 * 1.01
    assert np.diff(out.time)[:50] == pytest.approx(0.01, abs=1e-8) and np.diff(out.time)[-1] == pytest.approx(0.05)


def test_uncompressed_binary_fileid_3_is_exact(tmp_path):
    t, values = _run()
    out = read_output(write_binary(tmp_path / "run3.outb", t, NAMES, UNITS, values, 3))
    assert out.file_id == 3
    assert all(np.array_equal(out.channels[n], values[:, k]) for k, n in enumerate(NAMES[1:]))


def test_fileid_4_takes_the_name_length_from_the_header(tmp_path):
    t, values = _run(n=50)
    names = ["Time", "B1N001Fx", "AVeryLongChannelName", "RootMyb1", "YawBrFzp", "Constant"]
    units = ["s", "N/m", "kN-m", "kN-m", "kN", "-"]
    out = read_output(write_binary(tmp_path / "run4.outb", t, names, units, values, 4))
    assert out.names == names and out.units["AVeryLongChannelName"] == "kN-m"


@pytest.mark.parametrize("delimiter,encoding,newline", [("\t", "latin-1", "\r\n"), (" ", "utf-8", "\n")])
def test_text_round_trip_to_four_significant_digits(tmp_path, delimiter, encoding, newline):
    t, values = _run()
    path = write_text(tmp_path / "run.out", t, NAMES, UNITS, values, delimiter=delimiter, encoding=encoding,
                      newline=newline)
    out = read_output(path)
    assert out.file_id == 0 and out.names == NAMES and out.units["RootMyb1"] == "kN·m"
    assert "slewing_model test" in out.description
    got = np.column_stack([out.channels[n] for n in NAMES[1:]])
    # ES10.3E2: 4 significant digits, a relative rounding error of at most 5e-4
    assert np.all(np.abs(got - values) <= 5e-4 * np.abs(values))
    assert np.allclose(out.time, t, atol=5e-5)                          # F10.4


# --- errors -------------------------------------------------------------------------------------

def test_truncated_binary_file_is_refused_naming_the_file(tmp_path):
    t, values = _run()
    whole = write_binary(tmp_path / "whole.outb", t, NAMES, UNITS, values, 2).read_bytes()
    for cut in (len(whole) - 10, 40):                                   # in the data; in the header
        path = tmp_path / f"cut{cut}.outb"
        path.write_bytes(whole[:cut])
        with pytest.raises(OpenFastFormatError, match="truncated") as err:
            read_output(path)
        assert str(path) in str(err.value)
    assert "401 rows of 5 channels" in _message(tmp_path / f"cut{len(whole) - 10}.outb")


def _message(path):
    with pytest.raises(OpenFastFormatError) as err:
        read_output(path)
    return str(err.value)


@needs_data
def test_truncated_real_file_is_refused(tmp_path):
    data = (DATA / V8).read_bytes()
    path = tmp_path / "Test18_cut.outb"
    path.write_bytes(data[: len(data) // 2])
    message = _message(path)
    assert "truncated" in message and "9601 rows of 38 channels" in message and str(path) in message


def test_unknown_fileid_is_refused(tmp_path):
    t, values = _run(n=10)
    data = bytearray(write_binary(tmp_path / "ok.outb", t, NAMES, UNITS, values, 2).read_bytes())
    data[:2] = (7).to_bytes(2, "little")
    path = tmp_path / "seven.outb"
    path.write_bytes(bytes(data))
    message = _message(path)
    assert "FileID = 7" in message and str(path) in message


def test_text_file_with_a_cut_last_row_is_refused(tmp_path):
    t, values = _run(n=20)
    path = write_text(tmp_path / "run.out", t, NAMES, UNITS, values)
    path.write_bytes(path.read_bytes()[:-30])
    message = _message(path)
    assert "values for 6 channels" in message and "truncated" in message and str(path) in message


def test_text_file_without_a_time_line_is_refused(tmp_path):
    path = tmp_path / "notes.out"
    path.write_text("just\nsome\ntext\n")
    assert "no channel-name line starting with 'Time'" in _message(path)


def test_missing_channel_is_named_with_the_file(tmp_path):
    t, values = _run(n=10)
    out = read_output(write_binary(tmp_path / "run.outb", t, NAMES, UNITS, values, 2))
    with pytest.raises(MissingChannelError) as err:
        out.channel("RootMzb1")
    assert "RootMzb1" in str(err.value) and "run.outb" in str(err.value)
    assert isinstance(err.value, KeyError) and isinstance(err.value, ValueError)
    assert out.channel("rootmyb1")[2] == "RootMyb1"                   # names are case-insensitive, as in OpenFAST


# --- the shipped real files against their README (statistics computed with openfast_io) ---------------

# (file, rows, t0, t_end, dt, channels) from the README table
SPANS = [
    (V8, 9601, 0.0, 60.0, 0.00625, 39), (V7, 4801, 0.0125, 60.0125, 0.0125, 39),
    (TEST.format(1), 6001, 60.0, 660.0, 0.1, 113), (TEST.format(2), 6001, 60.0, 660.0, 0.1, 113),
    (TEST.format(3), 6001, 60.0, 660.0, 0.1, 113), (IEA, 4001, 0.0, 100.0, 0.025, 151),
    (WINDPACT, 801, 0.0, 40.0, 0.05, 23),
]


@needs_data
@pytest.mark.parametrize("name,rows,t0,t1,dt,channels", SPANS, ids=[s[0][:24] for s in SPANS])
def test_real_file_layout_matches_the_readme(name, rows, t0, t1, dt, channels):
    out = read_output(DATA / name)
    assert out.time.size == rows and len(out.channels) == channels
    # times are stored in single precision (60.0000089 for 60)
    assert out.time[0] == pytest.approx(t0, abs=1e-5) and out.time[-1] == pytest.approx(t1, abs=1e-4)
    assert np.allclose(np.diff(out.time), dt, rtol=1e-5)
    assert all(np.all(np.isfinite(v)) for v in out.channels.values())


# ../shared/data/openfast/README.md, its line "Statistics over 0-60 s" of the FAST v8 file: mean +- standard
# deviation, printed to the digit shown (Wind1VelX: the README prints 1.17 for the standard deviation, the
# data give 1.1648 -- openfast_io 5.0.0 decodes every value of this file identically to this reader -- so only
# its mean is compared)
V8_STATISTICS = [
    ("Wind1VelX", 12.94, None, 0.005), ("RotSpeed", 12.08, 0.28, 0.005), ("BldPitch1", 3.47, 2.51, 0.005),
    ("RootMyb1", 8126, 1530, 0.5), ("RootMxb1", 854, 2536, 0.5), ("RootFzb1", 600, 126, 0.5),
    ("YawBrFxp", 595, 159, 0.5), ("YawBrFzp", -3477, 22, 0.5), ("YawBrMyp", 1204, 944, 0.5),
    ("YawBrMzp", -396, 846, 0.5), ("GenPwr", 4874, 312, 0.5),
]


@needs_data
@pytest.mark.parametrize("channel,mean,std,half_digit", V8_STATISTICS, ids=[s[0] for s in V8_STATISTICS])
def test_fast_v8_statistics_match_the_readme(channel, mean, std, half_digit):
    out = read_output(DATA / V8)
    x = out.channels[channel]
    # Both readers decode the same int16 values with the same slope and offset, so they agree to rounding
    # (float32 vs float64 arithmetic: far below one quantisation level); the README rounds to the digit shown.
    # Tolerance: half that digit plus one quantisation level (range / 65535) for the arithmetic and for the
    # standard deviation's n vs n - 1 (a relative 5e-5 here).
    level = (x.max() - x.min()) / 65535
    assert x.mean() == pytest.approx(mean, abs=half_digit + level)
    if std is not None:
        assert x.std() == pytest.approx(std, abs=half_digit + level)


# README: pitch ranges ("varies from -0.02 to 7.85 deg", "0 - 8.65", ...), printed to the digit shown
PITCH_RANGES = [
    (V8, "BldPitch1", -0.02, 7.85, 0.005), (V7, "BldPitch1", 0.0, 8.65, 0.005),
    (TEST.format(1), "BldPitch1", 0.0, 0.0, 0.005), (TEST.format(2), "BldPitch1", 0.0, 10.2, 0.05),
    (TEST.format(3), "BldPitch1", 8.96, 17.7, 0.05), (IEA, "BldPitch1", 1.05, 10.0, 0.05),
    (WINDPACT, "BldPitch2", 2.6, 13.3, 0.05),
]


@needs_data
@pytest.mark.parametrize("name,channel,lo,hi,half_digit", PITCH_RANGES, ids=[p[0][:24] for p in PITCH_RANGES])
def test_real_pitch_ranges_match_the_readme(name, channel, lo, hi, half_digit):
    out = read_output(DATA / name)
    x = out.channels[channel]
    assert out.units[channel] == "deg"
    assert x.min() == pytest.approx(lo, abs=half_digit) and x.max() == pytest.approx(hi, abs=half_digit)


@needs_data
def test_real_files_other_readme_figures():
    v8 = read_output(DATA / V8)
    # resolution examples of the README: RootMyb1 0.18 kN m, YawBrMyp 0.11 kN m, YawBrFxp 0.019 kN (range / 65535)
    for channel, resolution, half_digit in (("RootMyb1", 0.18, 0.005), ("YawBrMyp", 0.11, 0.005),
                                            ("YawBrFxp", 0.019, 0.0005)):
        x = v8.channels[channel]
        assert (x.max() - x.min()) / 65535 == pytest.approx(resolution, abs=half_digit)
    test3 = read_output(DATA / TEST.format(3))
    assert test3.channels["BldPitch1"].mean() == pytest.approx(14.6, abs=0.05)   # "mean 14.6 deg"
    windpact = read_output(DATA / WINDPACT)
    wind = windpact.channels["Wind1VelX"]                                     # "measured 11.9 +- 1.41 m/s"
    assert wind.mean() == pytest.approx(11.9, abs=0.05) and wind.std() == pytest.approx(1.41, abs=0.005)
    for k, sigma in ((1, 0.31), (2, 0.46), (3, 0.76)):                          # "wave elevation sigma"
        assert read_output(DATA / TEST.format(k)).channels["WaveElev"].std() == pytest.approx(sigma, abs=0.005)


@needs_data
def test_real_units_are_read_as_the_files_spell_them():
    assert read_output(DATA / V8).units["RootMyb1"] == "kN·m"               # Latin-1 0xB7 in the binary
    assert read_output(DATA / V7).units["RootMyc1"] == "kN·m"
    assert read_output(DATA / IEA).units["RootMyb1"] == "kN-m"              # OpenFAST 2020
    windpact = read_output(DATA / WINDPACT)                                    # Latin-1 text with CRLF
    assert windpact.units["RootMyb2"] == "kN·m" and windpact.units["Time"] == "s"
    assert "WindPACT 1.5 MW" in windpact.description


@needs_data
def test_fast_v7_trailing_rows_after_the_declared_count_are_ignored():
    # the v7 file holds 12001 rows of int16 after its header, of which the header declares 4801;
    # the series is continuous up to row 4801 and jumps after it (an older run's data)
    out = read_output(DATA / V7)
    assert out.time.size == 4801
    x = out.channels["RootMyc1"]
    assert np.max(np.abs(np.diff(x))) < 0.05 * (x.max() - x.min())


def test_output_file_is_plain_data():
    out = OutputFile("x.out", np.array([0.0, 1.0]), {"Time": np.array([0.0, 1.0])}, {"Time": "s"})
    assert out.find("TIME") == "Time" and out.find("Nope") is None and math.isfinite(out.time[-1])
