#!/usr/bin/env python3
"""Whether two `rotor bench --json` reports are the same, timings aside: every number (and
flag) under a timing key is masked, the rest compared as it stands; the first difference is
printed. Used by .ci/slurm on a merged report and one run's."""
import json, sys
TIMING = {"median_s", "min_s", "repeats", "seconds", "ratio", "final_ratio", "ratio_of_minima",
          "times", "ratios", "client_seconds", "rust_seconds", "rust_is_bound", "protocol_s",
          "process_s", "environment"}
def mask(v, t=False):
    if isinstance(v, dict):
        return {k: mask(x, t or k in TIMING) for k, x in v.items()}
    if isinstance(v, list):
        return [mask(x, t) for x in v]
    if t and isinstance(v, (int, float, bool)) and v is not None:
        return "timing"
    return v
a, b = (mask(json.load(open(f))) for f in sys.argv[1:3])
if a != b:
    def diff(x, y, path=""):
        if type(x) != type(y) or not isinstance(x, (dict, list)):
            if x != y: print(f"{path}: {str(x)[:80]} != {str(y)[:80]}"); return True
            return False
        if isinstance(x, dict):
            for k in set(x) | set(y):
                if diff(x.get(k), y.get(k), f"{path}.{k}"): return True
            return False
        if len(x) != len(y): print(f"{path}: {len(x)} != {len(y)} items"); return True
        return any(diff(p, q, f"{path}[{i}]") for i, (p, q) in enumerate(zip(x, y)))
    diff(a, b); sys.exit(1)
print("same, timings aside")
