"""Command line: ``armdyn verify`` prints the solver's accuracy figures (pendulum period, energy
and momentum conservation, constraint drift, cross-check against recursive Newton–Euler)."""

from __future__ import annotations

import argparse
import sys


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="armdyn", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("verify", help="print accuracy figures against closed forms and RNEA")
    args = parser.parse_args(argv)
    if args.command == "verify":
        from armdyn.verify import main as verify_main

        return verify_main()
    return 1


if __name__ == "__main__":
    sys.exit(main())
