"""scripts/slurm/submit.sh and sweep.sbatch without a cluster: a fake
`sbatch` on PATH records what it was asked, a fake posebench what it was run
with. The real single-node Slurm run is tests/test_cli_slurm.cpp."""
import os
import shlex
import stat
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SLURM = os.path.join(ROOT, "scripts", "slurm")


def executable(path, text):
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)


class Submit(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        d = self.tmp.name
        self.log = os.path.join(d, "sbatch.log")
        # Each call: its arguments on one line; prints a job id (600, 601, ...).
        executable(os.path.join(d, "sbatch"),
                   "#!/bin/sh\nn=$(wc -l < %s 2>/dev/null || echo 0)\n"
                   "for a in \"$@\"; do printf '%%s\\t' \"$a\"; done >> %s\necho >> %s\n"
                   "echo $((600 + n))\\;cluster\n" % (self.log, self.log, self.log))
        self.posebench = os.path.join(d, "posebench")
        executable(self.posebench, "#!/bin/sh\nexit 0\n")

    def tearDown(self):
        self.tmp.cleanup()

    def submit(self, *args):
        env = dict(os.environ, PATH=self.tmp.name + ":" + os.environ["PATH"], POSEBENCH=self.posebench)
        return subprocess.run([os.path.join(SLURM, "submit.sh"), *args], cwd=self.tmp.name, env=env,
                              capture_output=True, text=True)

    def calls(self):
        with open(self.log) as f:
            return [line.rstrip("\n").rstrip("\t").split("\t") for line in f]

    def test_array_of_n_then_a_merge_that_waits_for_it(self):
        out = os.path.join(self.tmp.name, "out")
        r = self.submit("configs/experiments/demo.yaml", "7", out, "--", "--cache", "/s/c",
                        "--sbatch", "--partition=cpu --time=1:00:00")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.split(), ["array", "600", "merge", "601"])
        array, merge = self.calls()
        self.assertIn("--array=0-6", array)
        self.assertIn("--partition=cpu", array)
        self.assertIn("--time=1:00:00", array)
        self.assertIn("--chdir=" + ROOT, array)
        i = array.index(os.path.join("scripts", "slurm", "sweep.sbatch"))
        self.assertEqual(array[i + 1:], ["configs/experiments/demo.yaml", out, "--cache", "/s/c"])
        self.assertIn("--dependency=afterany:600", merge)
        self.assertIn("--partition=cpu", merge)
        self.assertEqual(merge[-2:], [os.path.join("scripts", "slurm", "merge.sbatch"), out])
        self.assertTrue(os.path.isdir(os.path.join(out, "slurm")))

    def test_out_defaults_to_results_of_the_file_stem(self):
        r = self.submit("configs/experiments/demo.yaml", "2")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.calls()[1][-1], "results/demo")

    def test_bad_arguments_are_exit_2_and_submit_nothing(self):
        for args, words in ((["configs/experiments/demo.yaml", "0"], "positive integer"),
                            (["configs/experiments/demo.yaml", "x"], "positive integer"),
                            (["configs/experiments/nope.yaml", "2"], "no such experiment"),
                            (["configs/experiments/demo.yaml"], "usage")):
            r = self.submit(*args)
            self.assertEqual(r.returncode, 2, args)
            self.assertIn(words, r.stderr, args)
        self.assertFalse(os.path.exists(self.log))


class SweepTask(unittest.TestCase):
    def run_task(self, task, count, lo, hi, cpus=None):
        with tempfile.TemporaryDirectory() as d:
            argfile = os.path.join(d, "args")
            fake = os.path.join(d, "posebench")
            executable(fake, "#!/bin/sh\necho \"OMP=$OMP_NUM_THREADS $*\" > %s\n" % shlex.quote(argfile))
            env = dict(os.environ, POSEBENCH=fake, SLURM_ARRAY_TASK_ID=str(task),
                       SLURM_ARRAY_TASK_COUNT=str(count), SLURM_ARRAY_TASK_MIN=str(lo),
                       SLURM_ARRAY_TASK_MAX=str(hi))
            env.pop("SLURM_CPUS_PER_TASK", None)
            if cpus:
                env["SLURM_CPUS_PER_TASK"] = str(cpus)
            r = subprocess.run([os.path.join(SLURM, "sweep.sbatch"), "exp.yaml", "OUT", "--cache", "c"],
                               env=env, capture_output=True, text=True)
            args = None
            if os.path.exists(argfile):
                with open(argfile) as f:
                    args = f.read().split()
            return r, args

    def test_task_i_of_n_runs_shard_i_of_n_on_its_cpus(self):
        r, args = self.run_task(2, 3, 0, 2)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(args, ["OMP=1", "run", "exp.yaml", "--out", "OUT", "--jobs", "1", "-q",
                                "--shard", "2/3", "--cache", "c"])
        r, args = self.run_task(0, 3, 0, 2, cpus=4)
        self.assertEqual(args[0], "OMP=4")

    def test_an_array_not_numbered_from_zero_is_refused(self):
        r, args = self.run_task(1, 3, 1, 3)
        self.assertEqual(r.returncode, 2)
        self.assertIn("must be 0-2", r.stderr)
        self.assertIsNone(args)


if __name__ == "__main__":
    unittest.main()
