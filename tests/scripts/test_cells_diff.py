"""scripts/cells_diff.py on two tiny cells.csv files."""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import cells_diff  # noqa: E402

HEADER = "table,experiment,kind,scenario,measure,method,ours_k,n,ours,thesis\n"


def write(rows):
    f = tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False)
    f.write(HEADER + "".join(rows))
    f.close()
    return f.name


class CellsDiffTest(unittest.TestCase):
    def test_direction(self):
        self.assertEqual(cells_diff.direction(1.0, 0.5, 0.1), "toward")
        self.assertEqual(cells_diff.direction(0.5, 1.0, 0.1), "away")
        self.assertEqual(cells_diff.direction(0.5, 0.503, 0.1), "same")

    def test_table_keeps_real_sensor_robustness_cells(self):
        before = write(["4.1,t,main,table_astra,robustness,shot,60,60,1,0.1\n",
                        "4.1,t,main,table_astra,time,shot,,,0.05,5.68\n",
                        "4.1,t,main,table_synthetic,robustness,shot,60,60,1,1\n",
                        "4.1,t,ablation,table_astra,robustness,shot,10,60,0.1667,0.1\n"])
        after = write(["4.1,t,main,table_astra,robustness,shot,30,60,0.5,0.1\n",
                       "4.1,t,main,table_synthetic,robustness,shot,50,60,0.8333,1\n"])
        try:
            cells_b = cells_diff.robustness_cells(before, ["table_astra", "table_kinect_one"])
            cells_a = cells_diff.robustness_cells(after, ["table_astra", "table_kinect_one"])
            self.assertEqual(list(cells_b), [("4.1", "table_astra", "shot")])
            text, counts = cells_diff.table(cells_b, cells_a)
            self.assertIn("| 4.1 | table_astra | shot | 60/60 | 30/60 | 10% | toward |", text)
            self.assertEqual(counts, {"toward": 1, "away": 0, "same": 0})
        finally:
            os.unlink(before)
            os.unlink(after)


if __name__ == "__main__":
    unittest.main()
