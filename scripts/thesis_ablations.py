#!/usr/bin/env python3
"""The ablation experiments of the thesis regeneration: each cause of a gap
between our tables and the thesis's (configs/thesis/ablations.yaml) switched
back in a copy of the experiments it concerns, so a reader sees the cells
that cause moves.

    thesis_ablations.py SPEC OUT_DIR        write OUT_DIR/NAME.yaml for every
                                            ablation experiment; print NAME
                                            and the path, one per line

An ablation names the experiments it copies and what it switches: `scenes`
(the scene sets kept; default all), `generator` (merged into each kept
scene's generator overrides, JSON merge patch: {warehouse: {wall: true}}),
`settings` (merged into the experiment's settings), `config` (other
top-level keys of the experiment replaced, e.g. perturb_deg; not name,
seed, scenes, settings, report or description), and `switches`: a list of
targeted switches applied after those, each with an optional
`experiments` (default: all of the ablation's) and `scenes` (default: all
kept) that it applies to, and any of `generator` (merged into each of
those scenes), `settings` (merged into each of those scenes' own settings
when `scenes` is given, else into the experiment's) and `config` (not with
`scenes`). The copy of experiment
E is named ablation_NAME_E, keeps E's report reference, and differs from E
only by the switch. Exit 2 with the file and field on a bad spec."""
import copy
import os
import sys

import yaml


class SpecError(Exception):
    def __init__(self, path, field, what):
        super().__init__("%s: %s: %s" % (path, field, what))


def merge_patch(base, patch):
    """RFC 7386 merge: dicts merge key by key, None deletes, anything else replaces."""
    if not isinstance(patch, dict):
        return copy.deepcopy(patch)
    out = copy.deepcopy(base) if isinstance(base, dict) else {}
    for k, v in patch.items():
        if v is None:
            out.pop(k, None)
        else:
            out[k] = merge_patch(out.get(k), v)
    return out


# Top-level keys of an experiment an ablation's `config` may not replace:
# the copy keeps the experiment's identity, trial seeds and report.
FIXED_KEYS = ("name", "seed", "scenes", "settings", "report", "description")


def ablation_name(ablation, experiment):
    return "ablation_%s_%s" % (ablation, experiment)


def load_spec(path):
    """The ablations of SPEC as a list of dicts, checked."""
    try:
        with open(path) as f:
            spec = yaml.safe_load(f)
    except OSError as e:
        raise SpecError(path, "", "cannot read (%s)" % e.strerror)
    except yaml.YAMLError as e:
        raise SpecError(path, "", "malformed YAML (%s)" % str(e).replace("\n", " "))
    if not isinstance(spec, dict) or not isinstance(spec.get("ablations"), list):
        raise SpecError(path, "ablations", "must be a list")
    seen = set()
    for i, a in enumerate(spec["ablations"]):
        where = "ablations[%d]" % i
        if not isinstance(a, dict):
            raise SpecError(path, where, "must be a mapping")
        for key in ("name", "cause", "switched"):
            if not isinstance(a.get(key), str) or not a[key]:
                raise SpecError(path, where + "." + key, "must be a non-empty string")
        if a["name"] in seen:
            raise SpecError(path, where + ".name", "'%s' appears twice" % a["name"])
        seen.add(a["name"])
        if not isinstance(a.get("experiments"), list) or not a["experiments"]:
            raise SpecError(path, where + ".experiments", "must be a non-empty list of experiment names")
        check_parts(path, where, a)
        if "scenes" in a and not (isinstance(a["scenes"], list) and a["scenes"]):
            raise SpecError(path, where + ".scenes", "must be a non-empty list of scene names")
        if "switches" in a:
            check_switches(path, where + ".switches", a)
        if not any(k in a for k in ("generator", "settings", "config", "switches")):
            raise SpecError(path, where, "switches nothing (give 'generator', 'settings', 'config' or 'switches')")
    return spec["ablations"]


def check_parts(path, where, d):
    """What a switch (an ablation's own, or a targeted one) merges in: generator, settings and config mappings,
    config without the fixed keys."""
    for key in ("generator", "settings", "config"):
        if key in d and not isinstance(d[key], dict):
            raise SpecError(path, where + "." + key, "must be a mapping")
    for key in d.get("config", {}):
        if key in FIXED_KEYS:
            raise SpecError(path, where + ".config." + key, "cannot be switched (use scenes, generator or settings)")


def check_switches(path, where, ablation):
    """The targeted switches of one ablation, checked."""
    if not isinstance(ablation["switches"], list) or not ablation["switches"]:
        raise SpecError(path, where, "must be a non-empty list")
    for i, sw in enumerate(ablation["switches"]):
        at = "%s[%d]" % (where, i)
        if not isinstance(sw, dict):
            raise SpecError(path, at, "must be a mapping")
        for key in sw:
            if key not in ("experiments", "scenes", "generator", "settings", "config"):
                raise SpecError(path, at + "." + key, "unknown key (experiments, scenes, generator, settings, config)")
        for key in ("experiments", "scenes"):
            if key in sw and not (isinstance(sw[key], list) and sw[key]):
                raise SpecError(path, at + "." + key, "must be a non-empty list of names")
        for e in sw.get("experiments", []):
            if e not in ablation["experiments"]:
                raise SpecError(path, at + ".experiments", "'%s' is not one of the ablation's experiments" % e)
        check_parts(path, at, sw)
        if not any(k in sw for k in ("generator", "settings", "config")):
            raise SpecError(path, at, "switches nothing (give 'generator', 'settings' or 'config')")
        if "config" in sw and "scenes" in sw:
            raise SpecError(path, at + ".config", "applies to the whole experiment: not with 'scenes'")


def derive(ablation, experiment, config, config_path="experiment"):
    """The ablation copy of one experiment config (a dict): renamed, its
    scenes filtered, the switch merged in."""
    out = copy.deepcopy(config)
    out["name"] = ablation_name(ablation["name"], experiment)
    out["description"] = "%s; ablation '%s': %s" % (config.get("description", experiment), ablation["name"],
                                                    ablation["switched"])
    keep = ablation.get("scenes")
    scenes = [s for s in out.get("scenes", []) if keep is None or s.get("name") in keep]
    if not scenes:
        raise SpecError(config_path, "scenes", "none of %s in experiment %s" % (keep, experiment))
    out["scenes"] = scenes
    # The ablation's own switch: every kept scene, the experiment's settings (its `scenes` only filtered them).
    apply_switch(out, {k: ablation[k] for k in ("generator", "settings", "config") if k in ablation}, config_path)
    for i, sw in enumerate(ablation.get("switches", [])):
        if "experiments" not in sw or experiment in sw["experiments"]:
            apply_switch(out, sw, config_path, " (switches[%d])" % i)
    return out


def apply_switch(out, sw, config_path, note=""):
    """Merges one switch into the experiment copy `out`: its generator into each of its scenes (sw's `scenes`,
    default all of out's), its settings into those scenes' own settings when sw names scenes, else into the
    experiment's, its config into the top-level keys."""
    targets = [s for s in out["scenes"] if "scenes" not in sw or s.get("name") in sw["scenes"]]
    for s in targets:
        if "generator" in sw:
            if "generate" not in s:
                raise SpecError(config_path, "scenes.%s" % s.get("name"),
                                "is not generated: no generator to switch" + note)
            s["generator"] = merge_patch(s.get("generator", {}), sw["generator"])
        if "settings" in sw and "scenes" in sw:
            s["settings"] = merge_patch(s.get("settings", {}), sw["settings"])
    if "settings" in sw and "scenes" not in sw:
        out["settings"] = merge_patch(out.get("settings", {}), sw["settings"])
    for key, value in sw.get("config", {}).items():
        out[key] = copy.deepcopy(value)


def pairs(ablations):
    """(ablation, experiment as reported, its ablation copy) for every ablation and experiment."""
    return [(a["name"], e, ablation_name(a["name"], e)) for a in ablations for e in a["experiments"]]


def write_all(spec_path, out_dir, config_dir):
    ablations = load_spec(spec_path)
    os.makedirs(out_dir, exist_ok=True)
    written = []
    for a in ablations:
        for e in a["experiments"]:
            src = os.path.join(config_dir, e + ".yaml")
            try:
                with open(src) as f:
                    config = yaml.safe_load(f)
            except OSError:
                raise SpecError(spec_path, "ablations.%s.experiments" % a["name"], "no config %s" % src)
            d = derive(a, e, config, src)
            path = os.path.join(out_dir, d["name"] + ".yaml")
            with open(path, "w") as f:
                f.write("# Derived from %s by scripts/thesis_ablations.py (%s): do not edit.\n" % (src, spec_path))
                yaml.safe_dump(d, f, sort_keys=False, default_flow_style=None)
            written.append((d["name"], path))
    return written


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2 or argv[0] in ("-h", "--help"):
        print(__doc__.strip(), file=sys.stderr)
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    spec, out_dir = argv
    try:
        for name, path in write_all(spec, out_dir, os.path.dirname(spec) or "."):
            print(name, path)
    except SpecError as e:
        print("thesis_ablations.py: %s" % e, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
