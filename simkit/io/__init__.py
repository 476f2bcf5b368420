"""HDF5 input/output, the only stage that knows HDF5: the schema (:mod:`.schema`), the block writer, the lazy
reader, and the checks on an output path."""
from .campaign_index import write_campaign_index
from .output import check_output
from .reader import Array, Dataset, open_dataset
from .schema import SCHEMA, SCHEMA_VERSION, Field, SchemaError, field
from .solutions import read_solution, solution_names, write_solution
from .writer import Writer

__all__ = ["Array", "Dataset", "Field", "SCHEMA", "SCHEMA_VERSION", "SchemaError", "Writer", "check_output",
           "field", "open_dataset", "read_solution", "solution_names", "write_campaign_index", "write_solution"]
