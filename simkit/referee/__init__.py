"""Referee: score any navigation estimate against a simkit file's truth, run third-party filters through a
plugin interface, and check scenarios against golden statistics (``simkit score``, ``simkit regress``).

Arrays in, arrays out: estimates are :class:`simkit.solution.Solution` objects (from ``/solutions`` or a CSV).
"""
from .compare import Errors, compare
from .conventions import quat_to_simkit, solution_from_ned
from .csvfile import read_csv
from .errors import RefereeInputError
from .plugin import GnssEpoch, ImuSample, RunResult, TrueInitialState, run_filter
from .report import file_start, load_estimate, to_json, to_markdown, write_run_outputs
from .score import Score, score
from .spec import Spec, load_spec, parse_spec
from .truth import Truth, read_truth, truth_at

__all__ = ["Errors", "GnssEpoch", "ImuSample", "RefereeInputError", "RunResult", "Score", "Spec", "TrueInitialState",
           "Truth", "compare", "file_start", "load_estimate", "load_spec", "parse_spec", "quat_to_simkit",
           "read_csv", "read_truth", "run_filter", "score", "solution_from_ned", "to_json", "to_markdown",
           "truth_at", "write_run_outputs"]
