"""The dask comparison (see dask_driver.py): geods.dask on 1 worker process(es)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dask_driver import main  # noqa: E402

if __name__ == "__main__":
    main(1)
