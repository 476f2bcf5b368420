"""``python -m benchmarks``: the same as ``python benchmarks/run_all.py`` (see there)."""
import runpy
from pathlib import Path

if __name__ == "__main__":  # not in the interpreters that multiprocessing spawns from this one
    runpy.run_path(str(Path(__file__).resolve().parent / "run_all.py"), run_name="__main__")
