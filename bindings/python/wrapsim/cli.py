"""The `wrapsim` command (also `python3 -m wrapsim`).

Subcommands:
  info      the library in use: its path, version and build features
Exit status: 0 on success, 2 for bad input or a library that cannot be loaded.
"""

import argparse
import sys

from . import _lib as L


def _info(args):
    try:
        lib = L.lib()
    except L.LibraryError as e:
        print(f"wrapsim: {e}", file=sys.stderr)
        return 2
    features = lib.ws_build_features()
    names = [name for bit, name in ((L.WS_FEATURE_CCD, "libccd"),) if features & bit]
    print(f"libwrapsim {lib.ws_version_string().decode()}")
    print(f"library:  {lib._wrapsim_path}")
    print(f"binding:  {L.BINDING_VERSION}")
    print(f"features: {', '.join(names) if names else 'none'}")
    return 0


def build_parser():
    """The argument parser of the command (exposed for the tests and the docs)."""
    parser = argparse.ArgumentParser(
        prog="wrapsim",
        description="Simulation of stretch-wrapped loads: run a load file through its test.")
    parser.add_argument("--version", action="version",
                        version=f"wrapsim (binding) {L.BINDING_VERSION}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    p = sub.add_parser("info", help="the library in use: path, version, build features")
    p.set_defaults(func=_info)
    return parser


def main(argv=None):
    """Run the command with `argv` (default sys.argv[1:]); return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return 2
    return args.func(args)
