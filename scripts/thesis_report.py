#!/usr/bin/env python3
"""Writes results/thesis/README.md and cells.csv from the raw results of scripts/thesis.sh.

    scripts/thesis_report.py OUT EXPERIMENT... [--ablations FILE] [--scorecard-json FILE]

The code is the package scripts/thesis_report/ (--help: cli.py's text).
"""
import sys

from thesis_report.cli import main

if __name__ == "__main__":
    sys.exit(main())
