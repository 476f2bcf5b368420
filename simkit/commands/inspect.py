"""``simkit inspect FILE.h5``: groups, datasets, shapes, units, rates, durations and scenario provenance."""
from __future__ import annotations


def add_parser(sub):
    p = sub.add_parser("inspect", help="summarise a simkit HDF5 file",
                       description="Print the groups, datasets (shape, dtype, units), rates and durations of a file.")
    p.add_argument("file", help="simkit HDF5 file")
    return p


def run(args) -> int:
    from ..io import open_dataset

    with open_dataset(args.file) as ds:
        a = ds.attrs
        print(f"{ds.path}: simkit schema {a['schema_version']} (written by simkit {a.get('simkit_version', '?')}, "
              f"{a.get('created_utc', '?')})")
        print(f"scenario: {ds.scenario_name}   seed: {a.get('seed', '?')}   start: GPS week "
              f"{a.get('start_gps_week', '?')} sow {float(a.get('start_gps_sow', float('nan'))):.3f}")
        for group in ("truth", "imu", "gnss"):
            rate, dur = ds.rate_hz(group), ds.duration_s(group)
            if rate is not None:
                print(f"/{group}: {rate:g} Hz, {dur:g} s, {ds[group + '/t'].shape[0]} samples")
        width = max((len(n) for n, _ in ds.datasets()), default=10) + 1
        for name, d in ds.datasets():
            shape = "x".join(map(str, d.shape)) or "scalar"
            print(f"  /{name:<{width}} {shape:>16} {str(d.dtype):>8}  {d.attrs.get('units', '')}")
    return 0
