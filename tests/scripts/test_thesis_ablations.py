"""scripts/thesis_ablations.py: the copy of an experiment differs from it by
the switch alone (scenes kept, generator and settings merged), the real
configs/thesis/ablations.yaml derives a config per experiment, and a bad
spec exits 2 naming the file and the field."""
import os
import subprocess
import sys
import tempfile
import unittest

import yaml

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import thesis_ablations as ta  # noqa: E402

EXPERIMENT = {
    "name": "table_x", "description": "LS5", "seed": 1, "object": "ls5",
    "scenes": [
        {"name": "warehouse_synthetic", "generate": "w.yaml", "generator": {"images": 30, "warehouse": {"wall": False}},
         "settings": {"views": {"views": 12}}},
        {"name": "table_astra", "generate": "t.yaml", "generator": {"images": 60}},
    ],
    "settings": {"verify": {"score": "inliers"}, "views": {"follow_scene": True}},
    "report": {"reference_table": "4.1"},
}


def spec(**over):
    a = {"name": "planes", "cause": "two planes", "switched": "wall: true", "experiments": ["table_x"]}
    a.update(over)
    return a


class Derive(unittest.TestCase):
    def test_merge_patch(self):
        self.assertEqual(ta.merge_patch({"a": {"b": 1, "c": 2}, "d": 3}, {"a": {"b": 5}, "d": None}),
                         {"a": {"b": 5, "c": 2}})
        self.assertEqual(ta.merge_patch({"a": [1, 2]}, {"a": [3]}), {"a": [3]})

    def test_generator_switch_on_kept_scenes_only(self):
        d = ta.derive(spec(scenes=["warehouse_synthetic"], generator={"warehouse": {"wall": True}}), "table_x",
                      EXPERIMENT)
        self.assertEqual(d["name"], "ablation_planes_table_x")
        self.assertEqual([s["name"] for s in d["scenes"]], ["warehouse_synthetic"])
        self.assertEqual(d["scenes"][0]["generator"], {"images": 30, "warehouse": {"wall": True}})
        self.assertEqual(d["settings"], EXPERIMENT["settings"])
        self.assertEqual(d["report"], EXPERIMENT["report"])
        self.assertEqual(d["seed"], EXPERIMENT["seed"])  # same trial seeds as the experiment it copies
        self.assertEqual(EXPERIMENT["scenes"][0]["generator"]["warehouse"], {"wall": False})  # input untouched

    def test_settings_switch_keeps_everything_else(self):
        d = ta.derive(spec(name="views", settings={"views": {"follow_scene": False}}), "table_x", EXPERIMENT)
        self.assertEqual(len(d["scenes"]), 2)
        self.assertEqual(d["settings"], {"verify": {"score": "inliers"}, "views": {"follow_scene": False}})
        self.assertEqual(d["scenes"], EXPERIMENT["scenes"])

    def test_config_switch_replaces_top_level_keys_only(self):
        d = ta.derive(spec(config={"perturb_deg": 30, "perturb_mm": 100}), "table_x", EXPERIMENT)
        self.assertEqual((d["perturb_deg"], d["perturb_mm"]), (30, 100))
        self.assertEqual(d["scenes"], EXPERIMENT["scenes"])
        self.assertEqual(d["settings"], EXPERIMENT["settings"])
        self.assertEqual(d["seed"], EXPERIMENT["seed"])
        self.assertNotIn("perturb_deg", EXPERIMENT)

    def test_targeted_switches_reach_only_their_experiments_and_scenes(self):
        a = spec(name="text", experiments=["table_x", "table_y"], settings={"refine": {"crop": False}}, switches=[
            {"scenes": ["table_astra"], "settings": {"local": {"descriptor_radius_mm": 20}},
             "generator": {"noise": {"sigma": 2}}},
            {"experiments": ["table_y"], "scenes": ["warehouse_synthetic"], "generator": {"occlusion": {"p": 1}}},
            {"experiments": ["table_y"], "config": {"object": "liberty"}, "settings": {"views": {"views": 3}}},
        ])
        x = ta.derive(a, "table_x", EXPERIMENT)
        self.assertEqual(x["settings"], {"verify": {"score": "inliers"}, "views": {"follow_scene": True},
                                         "refine": {"crop": False}})
        self.assertEqual(x["scenes"][0], EXPERIMENT["scenes"][0])  # the warehouse: table_y's switch only
        self.assertEqual(x["scenes"][1]["settings"], {"local": {"descriptor_radius_mm": 20}})
        self.assertEqual(x["scenes"][1]["generator"], {"images": 60, "noise": {"sigma": 2}})
        self.assertEqual(x["object"], "ls5")
        y = ta.derive(a, "table_y", EXPERIMENT)
        self.assertEqual(y["scenes"][0]["generator"],
                         {"images": 30, "warehouse": {"wall": False}, "occlusion": {"p": 1}})
        self.assertEqual(y["scenes"][0]["settings"], {"views": {"views": 12}})  # scene settings untouched
        self.assertEqual(y["settings"]["views"], {"follow_scene": True, "views": 3})
        self.assertEqual(y["object"], "liberty")
        self.assertEqual(EXPERIMENT["scenes"][1], {"name": "table_astra", "generate": "t.yaml",
                                                   "generator": {"images": 60}})  # input untouched

    def test_no_scene_left_is_an_error(self):
        with self.assertRaises(ta.SpecError) as c:
            ta.derive(spec(scenes=["nowhere"], generator={"x": 1}), "table_x", EXPERIMENT, "cfg.yaml")
        self.assertIn("cfg.yaml: scenes", str(c.exception))

    def test_the_project_spec(self):
        with tempfile.TemporaryDirectory() as out:
            spec_path = os.path.join(ROOT, "configs", "thesis", "ablations.yaml")
            written = ta.write_all(spec_path, out, os.path.dirname(spec_path))
            names = [n for n, _ in written]
            self.assertEqual(len(names), len(set(names)))
            self.assertEqual([(a, e, n) for a, e, n in ta.pairs(ta.load_spec(spec_path))],
                             [(n.split("_")[1], n.split("_", 2)[2], n) for n in names])
            for name, path in written:
                with open(path) as f:
                    d = yaml.safe_load(f)
                self.assertEqual(d["name"], name)
                if name.startswith("ablation_planes_"):
                    self.assertEqual([s["name"] for s in d["scenes"]], ["warehouse_synthetic"])
                    self.assertTrue(d["scenes"][0]["generator"]["warehouse"]["wall"])
                if name.startswith("ablation_views_"):
                    self.assertFalse(d["settings"]["views"]["follow_scene"])


class BadSpec(unittest.TestCase):
    def run_spec(self, text):
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "ablations.yaml")
            with open(p, "w") as f:
                f.write(text)
            r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "thesis_ablations.py"), p,
                                os.path.join(d, "out")], capture_output=True, text=True)
            return r.returncode, r.stderr

    def test_errors_name_file_and_field(self):
        cases = [
            ("ablations: [\n", "malformed YAML"),
            ("ablations: {}\n", "ablations: must be a list"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [table_4_1]}\n",
             "ablations[0]: switches nothing"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [], settings: {}}\n",
             "ablations[0].experiments"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x], settings: {}}\n"
             "  - {name: a, cause: c, switched: s, experiments: [x], settings: {}}\n", "ablations[1].name"),
            ("ablations:\n  - {name: a, cause: '', switched: s, experiments: [x], settings: {}}\n",
             "ablations[0].cause"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [no_such], settings: {}}\n",
             "no config"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x], config: {seed: 2}}\n",
             "ablations[0].config.seed: cannot be switched"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x], config: 3}\n",
             "ablations[0].config: must be a mapping"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x], switches: []}\n",
             "ablations[0].switches: must be a non-empty list"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x], switches: [{scenes: [t]}]}\n",
             "ablations[0].switches[0]: switches nothing"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x],"
             " switches: [{experiments: [y], settings: {}}]}\n",
             "ablations[0].switches[0].experiments: 'y' is not one of the ablation's experiments"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x],"
             " switches: [{scenes: [t], config: {object: o}}]}\n",
             "ablations[0].switches[0].config: applies to the whole experiment"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x], switches: [{setting: {}}]}\n",
             "ablations[0].switches[0].setting: unknown key"),
            ("ablations:\n  - {name: a, cause: c, switched: s, experiments: [x],"
             " switches: [{config: {name: z}}]}\n",
             "ablations[0].switches[0].config.name: cannot be switched"),
        ]
        for text, want in cases:
            code, err = self.run_spec(text)
            self.assertEqual(code, 2, text)
            self.assertIn("ablations.yaml", err, text)
            self.assertIn(want, err, text)


if __name__ == "__main__":
    unittest.main()
