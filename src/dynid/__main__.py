import sys

from .cli.app import main

if __name__ == "__main__":  # worker processes (Dask, multiprocessing) import this module under another name
    sys.exit(main())
