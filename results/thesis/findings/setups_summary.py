"""The one-set-up probe (FINDINGS.md, "One set-up photographed 60 times"):
per cell of Table 4.1's plain real-sensor rows, the counts of the 10
set-ups, their spread, how many lie within 15 points of the thesis, and a
chi-square test that the set-ups share one rate.

    python3 results/thesis/findings/setups_summary.py OUT_ROOT

OUT_ROOT holds ablation_setupNN_table_4_1/records.jsonl (posebench run of
the configs derived from setups_spec.yaml); the thesis's values and the
reported counts come from results/thesis/cells.csv."""
import collections
import csv
import glob
import json
import os
import statistics
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import thesis_stats as st  # noqa: E402

SCENES = ("table_astra", "table_kinect_one")
METHODS = ("cvfh", "esf", "cesf", "shot", "fpfh")


def counts(out_root):
    """{(scene, method): [k per set-up]}, n per cell (every set-up the same n)."""
    per = collections.defaultdict(list)
    n_of = {}
    for d in sorted(glob.glob(os.path.join(out_root, "ablation_setup*_table_4_1"))):
        c = collections.Counter()
        for line in open(os.path.join(d, "records.jsonl")):
            r = json.loads(line)
            c[(r["scene"], r["descriptor"], "n")] += 1
            c[(r["scene"], r["descriptor"], "k")] += bool(r.get("correct"))
        for s in SCENES:
            for m in METHODS:
                per[(s, m)].append(c[(s, m, "k")])
                n_of[(s, m)] = c[(s, m, "n")]
    return per, n_of


def main(argv):
    per, n_of = counts(argv[1])
    ref = {(r["scenario"], r["method"]): r for r in csv.DictReader(open(os.path.join(ROOT, "results/thesis/cells.csv")))
           if r["kind"] == "main" and r["table"] == "4.1" and r["measure"] == "robustness"}
    differ = 0
    print("| sensor | method | reported | one set-up each (10): min / median / max | within 15 of the thesis | "
          "chi-square p | thesis |")
    print("|---|---|---:|---|---:|---:|---:|")
    for s in SCENES:
        for m in METHODS:
            ks, n = per[(s, m)], n_of[(s, m)]
            r = ref[(s, m)]
            thesis = float(r["thesis"])
            within = sum(abs(k / n - thesis) <= 0.15 + 1e-9 for k in ks)
            _, _, p = st.chi2_homogeneity(ks, n)
            differ += p < 0.05
            print("| %s | %s | %s/%s | %d / %g / %d of %d | %d of %d | %.2g | %.0f%% |" % (
                s.replace("table_", ""), m, r["ours_k"], r["n"], min(ks), statistics.median(ks), max(ks), n,
                within, len(ks), p, 100 * thesis))
    print("\ncells whose set-ups differ at p < 0.05: %d of %d" % (differ, len(SCENES) * len(METHODS)))


if __name__ == "__main__":
    main(sys.argv)
