"""HDF5 input/output (the only stage that knows HDF5): schema v1 writer and lazy reader."""
from .reader import Dataset, open_dataset
from .writer import Writer

__all__ = ["Dataset", "Writer", "open_dataset"]
