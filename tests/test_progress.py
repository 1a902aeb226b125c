"""Progress on stderr: tqdm's bar on a terminal, whole lines (no carriage return) in a file or pipe."""
import io
import re
import subprocess
import sys

from slewing_model.progress import PlainProgress, progress_bar

LINE = re.compile(r"^(?P<desc>.*): +(?P<pct>\d+) % \((?P<n>\d+)/(?P<total>\d+) (?P<unit>\w+), \d+ s\)$")


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def _lines(text):
    assert "\r" not in text and "\x1b" not in text, repr(text)
    return [LINE.match(line) for line in text.splitlines()]


def test_file_gets_whole_lines_that_reach_the_total():
    out = io.StringIO()
    bar = progress_bar(37, "harmonics", "harmonic", file=out)
    assert isinstance(bar, PlainProgress)
    for _ in range(37):
        bar.update(1)
    bar.close()
    lines = _lines(out.getvalue())
    assert all(lines), out.getvalue()
    counts = [int(m["n"]) for m in lines]
    percents = [int(m["pct"]) for m in lines]
    assert counts[0] == 0 and counts[-1] == 37 and percents[-1] == 100
    assert counts == sorted(set(counts)) and len(lines) <= 12      # a line per tenth, not per update
    assert all(m["desc"] == "harmonics" and m["unit"] == "harmonic" and m["total"] == "37" for m in lines)


def test_iterating_a_resumed_or_interrupted_loop():
    out = io.StringIO()
    seen = []
    for k in progress_bar(desc="drive", unit="step", iterable=range(50), file=out):
        seen.append(k)
        if k == 20:
            break
    assert seen == list(range(21))
    counts = [int(m["n"]) for m in _lines(out.getvalue())]
    assert counts[-1] == 20                                        # the count where it stopped, said once
    out = io.StringIO()
    with progress_bar(10, "study", "case", initial=7, file=out) as bar:
        bar.update(3)
    counts = [int(m["n"]) for m in _lines(out.getvalue())]
    assert counts[0] == 7 and counts[-1] == 10


def test_terminal_gets_the_bar():
    out = _Terminal()
    bar = progress_bar(5, "x", "it", file=out)
    bar.update(5)
    bar.close()
    assert not isinstance(bar, PlainProgress) and "\r" in out.getvalue()


def test_stderr_redirected_to_a_file_has_no_carriage_return(tmp_path):
    code = ("from slewing_model.progress import progress_bar\n"
            "for _ in progress_bar(desc='s', unit='step', iterable=range(1000)): pass\n")
    err = tmp_path / "err.txt"
    with open(err, "w") as fh:
        subprocess.run([sys.executable, "-c", code], stderr=fh, check=True)
    assert all(_lines(err.read_text())) and err.read_text().count("\n") >= 2
