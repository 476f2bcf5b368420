"""HDF5 input/output, the only stage that knows HDF5: the schema (:mod:`.schema`), the block writer, the lazy
file object (:mod:`.dataset`), the typed readers the consumers use (:mod:`.readers`: truth, IMU, GNSS, the truth
at any epoch) and the checks on an output path."""
from .campaign_index import write_campaign_index
from .output import check_output
from .dataset import Array, Dataset, open_dataset
from .readers import (TRUTH_CORE, Gnss, Imu, Truth, broadcast_ionosphere, gnss_signals, has, members, n_antennas,
                      n_samples, path_of, read_gnss, read_imu, read_reference, read_truth, reference_truth,
                      truth_at, truth_rows)
from .readers import broadcast_time_offsets
from .schema import SCHEMA, SCHEMA_VERSION, Field, SchemaError, field
from .solutions import read_solution, solution_names, write_solution
from .writer import Writer

__all__ = ["Array", "Dataset", "Field", "Gnss", "Imu", "SCHEMA", "SCHEMA_VERSION", "SchemaError", "TRUTH_CORE", "Truth",
           "Writer", "broadcast_ionosphere", "check_output", "field", "gnss_signals", "has", "members", "n_antennas",
           "n_samples", "path_of", "read_gnss", "read_imu", "read_reference", "read_truth", "reference_truth", "truth_at", "truth_rows", "open_dataset", "read_solution", "solution_names", "write_campaign_index", "write_solution"]
__all__ += ["broadcast_time_offsets"]
