"""``python3 -m geods --version`` prints the version as the geods CLI does."""
import argparse

from . import __version__


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python3 -m geods",
        description="geods: geometric data structures for computer graphics (Python package). "
        "The commands are in the geods CLI; see `geods --help`.")
    parser.add_argument("--version", action="version", version=f"geods {__version__}")
    parser.parse_args(argv)
    parser.print_help()


if __name__ == "__main__":
    main()
