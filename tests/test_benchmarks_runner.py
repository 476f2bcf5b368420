"""benchmarks/run_all.py and benchmarks/timing.py: the table lands between its markers and nowhere else, a failing
or peer-less benchmark says so in its row, and the A/B runner alternates the trees and collects each probe's line."""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import run_all  # noqa: E402
import timing  # noqa: E402


def test_table_replaces_only_the_text_between_the_markers(tmp_path):
    doc = tmp_path / "b.md"
    doc.write_text(f"# head\n\n{run_all.BEGIN}\nold table\n{run_all.END}\n\ntail\n")
    rows = [("truth", "fig | with bar", "1.0", "peer absent (x)", "-", "2026-01-01 00:00", "0.5 / 0.6")]
    run_all.write(run_all.markdown(rows, quick=True), doc)
    text = doc.read_text()
    assert text.startswith("# head\n\n" + run_all.BEGIN) and text.endswith(run_all.END + "\n\ntail\n")
    assert "old table" not in text and "| truth | fig / with bar | 1.0 | peer absent (x) | - |" in text
    assert "--quick" in text and "cores" in text
    run_all.write(run_all.markdown(rows, quick=False), doc)           # idempotent: one table, replaced
    assert doc.read_text().count(run_all.BEGIN) == 1
    assert run_all.previous_rows(doc) == [("truth", "fig / with bar", "1.0", "peer absent (x)", "-",
                                           "2026-01-01 00:00", "0.5 / 0.6")]


def test_a_failing_benchmark_is_a_row_and_the_others_still_run(monkeypatch):
    def broken(quick):
        raise RuntimeError("no disk")

    monkeypatch.setattr(run_all, "BENCHMARKS", {"a": broken, "b": lambda quick: [("f", "1", "2", "2.0x")]})
    rows = run_all.run(["a", "b"], quick=True)
    assert rows[0][:3] == ("a", "(did not run)", "failed: RuntimeError: no disk")
    assert rows[1][:5] == ("b", "f", "1", "2", "2.0x")


def test_ab_alternates_trees_and_collects_the_probe_line(tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "bb"
    a.mkdir(), b.mkdir()
    probe = "import sys, pathlib; print(len(pathlib.Path(sys.argv[1]).name), sys.argv[2])"
    rows = timing.ab([a, b], probe, ["name length", "extra"], rounds=2, extra_path="x")
    assert rows == [(str(a), ["1", "x"]), (str(b), ["2", "x"])] * 2
    assert "name length" in capsys.readouterr().out
