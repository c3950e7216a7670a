"""pendulum-fmu verify: whether a received FMU is what its build record says (pendulum_fmu.judging._verify)."""

from __future__ import annotations

import argparse


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `verify` and its options, each with its help, among the parser's commands."""
    verify = commands.add_parser(
        "verify",
        help="check a received FMU: its checksums, signature, binary and references",
        description="Check an FMU against what it records: each entry against its recorded SHA-256, the "
        "record's Ed25519 signature (with --public-key), this machine's binary rebuilt from the FMU's "
        "sources/ with the recorded compiler and flags (where that compiler is here), and the FMI-LS-REF "
        "references it carries replayed in fmpy and judged. Exit 0: nothing failed; 1: a check failed; "
        "2: not an FMU.",
    )
    verify.add_argument("fmu", metavar="FMU", help="the FMU to check")
    verify.add_argument(
        "--public-key", metavar="KEY", default=None, help="the Ed25519 public key (PEM) to check the signature with"
    )
    verify.add_argument(
        "--no-rebuild", action="store_true", help="do not rebuild the binary from its sources (the slowest check)"
    )
    verify.add_argument("--json", action="store_true", help="print the checks as JSON")
    verify.set_defaults(run=run)
    return verify


def run(args) -> int:
    """Run `pendulum-fmu verify` with the parsed arguments; returns the exit status."""
    from ..judging._verify import FAIL, checks_json, format_checks, verify_fmu

    checks = verify_fmu(args.fmu, public_key=args.public_key, rebuild=not args.no_rebuild)
    print(checks_json(args.fmu, checks) if args.json else format_checks(args.fmu, checks))
    return 1 if any(check.status == FAIL for check in checks) else 0
