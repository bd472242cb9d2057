"""Writes results/thesis/README.md and cells.csv from the raw results of
scripts/thesis.sh (command line: scripts/thesis_report.py; see cli.py).

Modules, in the order the data flows:
  schema       the trial record's schema; records.jsonl read strictly
  runs         wall times and loads (runs.jsonl, run_seconds.txt)
  results      the experiments' folders loaded (Experiment, Results)
  cells        counts per table cell against the thesis; cells.csv
  scorecard    the agreement scorecard
  conclusions  the thesis's conclusions (rules: scripts/thesis_verdicts.py)
  ablations    the ablation pairs and which gaps they explain
  formatting, tables, figures, differences, readme: the README's text
  cli          the command line
"""
