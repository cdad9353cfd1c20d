"""Callgrind helpers shared by the step benchmarks (benches/*/run.py).

Instructions per call come from the difference of a run with 2N calls and one
with N calls, divided by N: start-up, record parsing and the harness's fixed
costs cancel. Per-function costs come from callgrind_annotate's function table
(code inlined from another file, e.g. libm's log, is listed under that file).
"""
from __future__ import annotations

import os
import re
import subprocess
import sys

# one row of callgrind_annotate's function table: "Ir (pct) file:function [object]"
ROW = re.compile(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?(\S.*?)\s*(?:\[.*\])?$")


def sh(cmd, **kw):
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kw)


def collected(cmd, out, what, flags=()):
    """Total instructions of `cmd` under callgrind (with the extra callgrind `flags`),
    its output written to `out`."""
    r = subprocess.run(["valgrind", "--tool=callgrind", *flags, f"--callgrind-out-file={out}"] + cmd,
                       text=True, capture_output=True)
    m = re.search(r"Collected\s*:\s*(\d+)", r.stderr)
    if r.returncode or not m:
        sys.exit(f"callgrind failed for {what}:\n{r.stderr}")
    return int(m.group(1))


def difference(cmd_for, n, work, tag, flags=()):
    """(Ir per call, [output of the N run, output of the 2N run]); `cmd_for(calls)`
    is the command making `calls` calls."""
    ir, files = [], []
    for calls in (n, 2 * n):
        out = os.path.join(work, f"cg.{tag}.{calls}")
        ir.append(collected(cmd_for(calls), out, tag, flags))
        files.append(out)
    return (ir[1] - ir[0]) / n, files


def annotate(path, inclusive):
    """(Ir, file, function) rows of callgrind_annotate's function table."""
    flag = "--inclusive=yes" if inclusive else "--inclusive=no"
    lines = sh(["callgrind_annotate", "--threshold=100", flag, "--auto=no", path]).stdout.splitlines()
    start = next(i for i, l in enumerate(lines) if l.strip().endswith("file:function")) + 2
    for line in lines[start:]:
        if line.startswith("---"):
            break
        m = ROW.match(line)
        if m:
            file, _, fn = m.group(2).partition(":")
            yield int(m.group(1).replace(",", "")), file, fn


def self_costs(path, strip=""):
    """{file:function: self Ir} of a callgrind output; `strip` is a regex removed from
    the front of function names (the bench crate's own path)."""
    costs = {}
    for ir, file, fn in annotate(path, inclusive=False):
        key = f"{os.path.basename(file)}:{re.sub(strip, '', fn) if strip else fn}"
        costs[key] = costs.get(key, 0) + ir
    return costs


def self_costs_per_call(files, n, strip=""):
    """{file:function: self Ir per call} from the 2N − N difference of `files`."""
    a, b = self_costs(files[0], strip), self_costs(files[1], strip)
    per_fn = {f: (b.get(f, 0) - a.get(f, 0)) / n for f in set(a) | set(b)}
    return {f: c for f, c in per_fn.items() if c >= 0.5}


def inclusive(path, function):
    """Inclusive Ir of `function` (a suffix of its path) in a callgrind output; 0 when
    the function does not appear (inlined into its caller)."""
    return max((ir for ir, _, fn in annotate(path, inclusive=True) if fn.endswith(function)),
               default=0)
