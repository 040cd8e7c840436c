"""The ``rockdem`` command line: one sub-command per module, all over the Python API."""

from __future__ import annotations

import argparse
import importlib
import sys

# Modules that contribute a sub-command through ``register_cli(subparsers)``.
_COMMAND_MODULES = (
    "rockdem.run_cli",
    "rockdem.advisor",
    "rockdem.plots",
    "rockdem.animate",
    "rockdem.vtk_export",
    "rockdem.studies",
    "rockdem.reproduce",
)


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with every registered sub-command."""
    parser = argparse.ArgumentParser(
        prog="rockdem",
        description="3D rigid-block DEM for rocking masonry, with defensible damping.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in _COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:  # a module still being written: skip its command
                continue
            raise
        module.register_cli(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``rockdem`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except (ValueError, FileNotFoundError) as exc:
        print(f"rockdem {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
