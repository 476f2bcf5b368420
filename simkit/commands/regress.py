"""``simkit regress [SCENARIO ...]``: recompute bundled (or given) scenarios shortened and compare them with the
golden statistics; names every quantity that drifted. Exit 1 on drift, 2 on bad input."""
from __future__ import annotations

import json
from pathlib import Path

from ..errors import ScenarioError

USER_GOLDEN = "regress_golden.json"  # where --update writes without --golden: the bundled file stays as shipped


def add_parser(sub):
    p = sub.add_parser("regress", help="recompute scenarios and compare against golden statistics",
                       description="Recompute each scenario shortened (a few seconds) and compare its statistics "
                                   "(truth end state, IMU and GNSS error statistics) with the golden values, "
                                   "within tolerances; report which quantity drifted by how much. Default: every "
                                   "scenario of the bundled golden file. Exit 1 when anything drifted.")
    p.add_argument("scenarios", nargs="*", help="scenario names, TOML files or a directory of TOML files "
                                                "(default: the golden file's scenarios)")
    p.add_argument("--golden", metavar="FILE.json", help="golden statistics (default: the bundled file)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario key in every recomputed run (to see what a change moves)")
    p.add_argument("--update", action="store_true",
                   help=f"write golden statistics from this run instead of comparing: into --golden FILE, else "
                        f"./{USER_GOLDEN} (the bundled file is never rewritten)")
    return p


def _targets(items, golden: dict) -> list[tuple[str, object]]:
    """(name, scenario) pairs: names known to the golden file, TOML files, or every TOML in a directory."""
    from ..scenario.loader import bundled_names

    if not items:
        return [(name, name) for name in golden]
    out = []
    for item in items:
        path = Path(item)
        if path.is_dir():
            out += [(p.stem, p) for p in sorted(path.glob("*.toml"))]
        elif path.suffix == ".toml":
            if not path.is_file():
                raise ScenarioError("scenario", f"{item}: no such file")
            out.append((path.stem, path))
        elif item in bundled_names():
            out.append((item, item))
        else:
            raise ScenarioError("scenario", f"{item}: not a TOML file, a directory or a bundled scenario name")
    return out


def run(args) -> int:
    from tqdm import tqdm

    from ..referee import regress

    golden_path = Path(args.golden) if args.golden else regress.GOLDEN
    golden = {} if args.update and not golden_path.is_file() else regress.load_golden(golden_path)
    if args.update:  # starts from the golden read (the bundled one by default), written to a user path
        from ..io.output import check_output

        golden_path = check_output(args.golden or USER_GOLDEN, option="--golden")
    targets = _targets(args.scenarios, golden)
    if not args.update:
        missing = [name for name, _ in targets if name not in golden]
        if missing:
            raise ScenarioError("scenario", f"{missing[0]}: no golden statistics in {golden_path} (--update)")
    drifts = []
    for name, scenario in tqdm(targets, desc="regress", unit="scenario", leave=False):
        if args.update:
            duration = golden.get(name, {}).get("duration_s", regress.SHORT_S.get(name, regress.DEFAULT_SHORT_S))
            golden[name] = regress.golden_entry(scenario, duration, args.overrides)
            continue
        found = regress.check(name, scenario, golden[name], args.overrides)
        print(f"{name}: {len(golden[name]['quantities'])} quantities, "
              f"{'OK' if not found else f'{len(found)} drifted'}")
        drifts += found
    if args.update:
        from ..atomic import atomic_open

        with atomic_open(golden_path, "w") as f:
            f.write(json.dumps(golden, indent=1, sort_keys=True) + "\n")
        print(f"wrote {golden_path} ({len(targets)} scenarios updated); compare with --golden {golden_path}")
        return 0
    for d in drifts:
        print(f"DRIFT {d}")
    return 1 if drifts else 0
