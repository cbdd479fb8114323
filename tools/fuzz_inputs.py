#!/usr/bin/env python3
"""Seeded mutation fuzzer for wingman's input readers: scenarios, datasets and baselines.

    tools/fuzz_inputs.py --wingman build/app/wingman --workdir DIR
        [--scenario-mutants N] [--dataset-corruptions M] [--baseline-mutants K] [--seed S]
        [--time-budget SECONDS] [--jobs J] [--timeout T] [--mem-gib G] [--dataset DS]

Scenario mutants: a shipped scene (scenes/*.yaml) with 1 to 3 mutations (an extreme or odd
value, a deleted, duplicated or unknown key, a truncated file, random bytes, a changed indent,
two swapped lines), each run as `wingman run MUTANT --out OUT --no-plots -q --duration 2`
(`--frames 2` for a rendered scene). Dataset corruptions: a copy of a small rendered dataset
(`wingman render scenes/rendered_smoke.yaml --frames 4`, made once in DIR unless --dataset names
one) with one thing damaged (a PNG frame, a CSV line, an agent folder, dataset.yaml, a
sensor.yaml, the scenario.yaml), each run as `wingman slam COPY --out OUT --no-plots -q`.
Baseline mutants: baselines/smoke.yaml with 1 to 3 of the scenario mutations, each run as
`wingman check RESULTS --baseline MUTANT --junit OUT/junit.xml` on a smoke run made once in DIR;
there exit 0 or 1 (a verdict) with the report written is a clean run, and exit 2 must name the
mutant and leave no report.

Every run gets a timeout and an address-space cap, and a verdict:
  ok_ran              exit 0, outputs present and no non-finite value but those clean runs
                      have by design (an undefined metric, see output_nonfinite); for a
                      baseline mutant, exit 0 or 1 with its report written
  ok_refused          exit 2 and stderr names the input (the mutant or the dataset copy)
  ok_refused_unnamed  exit 2 but stderr names no input file            (finding)
  exit1_bad_input     exit 1, an internal error instead of a refusal   (finding)
  exit_other          any other exit status                            (finding)
  signal              killed by a signal we did not send               (finding)
  hang                still running at the timeout                     (finding)
  oom                 bad_alloc or an allocation failure on stderr     (finding)
  leftover            OUT exists after a failure, or a *.partial-* / *.old-* sibling of OUT
                      exists after the run                             (finding)
  nonfinite_output    exit 0 and metrics.json or a CSV holds NaN/inf (null in metrics.json)
                      beyond those                                     (finding)
  no_output           exit 0 but OUT has no metrics.json               (finding)
  harness_error       this script failed on the case (a traceback is printed)

DIR keeps mutants/NNNN.yaml, corrupt/NNNN/ (the damaged dataset copies that gave a finding),
stderr/NNNN.txt (head and tail) and outcomes.jsonl (one JSON object per run, written as runs
finish, with the argv to rerun it). The same --seed gives the same mutants. The summary is a
Markdown table of verdicts per kind and the first 20 findings; the exit status is 1 when there
is a finding, 0 when there is none, 2 when the dataset to corrupt cannot be made.
"""
import argparse
import concurrent.futures
import dataclasses
import json
import math
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import threading
import time
import traceback
import zlib
from pathlib import Path

try:
    import yaml  # node marks let a mutation edit one value in place and keep every comment
except ImportError:  # text-level mutations still work without it
    yaml = None

REPO = Path(__file__).resolve().parent.parent
OK_VERDICTS = {"ok_ran", "ok_refused"}
STDERR_KEEP = 2000  # characters kept from each end of a run's stderr
OOM_PATTERNS = ("bad_alloc", "Failed to allocate", "Cannot allocate memory", "Insufficient memory",
                "out of memory")


# ---------------------------------------------------------------------------------------------
# Text in and out: surrogateescape keeps every byte (a 0xff byte is '\udcff'), so mutations can
# work on str and the file written back holds exactly the bytes chosen.

def decode(data: bytes) -> str:
    return data.decode("utf-8", "surrogateescape")


def encode(text: str) -> bytes:
    return text.encode("utf-8", "surrogateescape")


def shorten(text: str, limit: int = 60) -> str:
    """A value as a mutation description shows it: long ones as their length."""
    def show(t):  # a raw byte as \xff, other odd characters escaped
        return t if t.isprintable() else encode(t).decode("ascii", "backslashreplace")
    if len(text) <= limit:
        return show(text)
    return f"<{len(text)} chars: {show(text[:12])}...>"


# ---------------------------------------------------------------------------------------------
# YAML entries: every mapping value and sequence item with its path and source marks.

@dataclasses.dataclass
class Entry:
    path: str
    key: object      # yaml key node, None for a sequence item
    value: object    # yaml value node
    parent: object   # the mapping or sequence node holding it


def compose(text: str):
    """The YAML node tree, or None when the text is no longer YAML PyYAML reads."""
    if yaml is None:
        return None
    try:
        return yaml.compose(text, Loader=yaml.SafeLoader)
    except (yaml.YAMLError, ValueError):
        return None


def entries(node, path: str = "") -> list:
    out = []
    if isinstance(node, yaml.MappingNode):
        for k, v in node.value:
            p = f"{path}.{k.value}" if path else str(k.value)
            out.append(Entry(p, k, v, node))
            out.extend(entries(v, p))
    elif isinstance(node, yaml.SequenceNode):
        for i, v in enumerate(node.value):
            p = f"{path}[{i}]"
            out.append(Entry(p, None, v, node))
            out.extend(entries(v, p))
    return out


def single_line(node) -> bool:
    """A scalar or flow collection on one line: its marks span exactly its text."""
    flow = isinstance(node, yaml.ScalarNode) or node.flow_style
    return flow and node.start_mark.line == node.end_mark.line


def indent_of(line: str) -> int:
    return len(line) - len(line.lstrip(" "))


def block_extent(lines: list, e: Entry) -> int:
    """Index of the first line after a block entry (its key line and its nested lines)."""
    first, col = e.key.start_mark.line, e.key.start_mark.column
    seq = isinstance(e.value, yaml.SequenceNode)
    for i in range(first + 1, len(lines)):
        s = lines[i].strip()
        if not s or s.startswith("#"):
            continue
        ind = indent_of(lines[i])
        if ind < col or (ind == col and not (seq and s.startswith("-"))):
            return i
    return len(lines)


def line_offsets(text: str) -> list:
    offs, pos = [], 0
    for line in text.splitlines(keepends=True):
        offs.append(pos)
        pos += len(line)
    offs.append(pos)
    return offs


# ---------------------------------------------------------------------------------------------
# Structural mutations: each takes (rng, text, entry list) and returns (new text, description),
# or None when it has nothing to act on.

NUMERIC_EXTREMES = ["0", "-1", "1e308", "-1e308", "1e-300", "-1e-300", "nan", ".nan", ".inf",
                    "-.inf", str(2**31), str(2**63), str(2**64), str(-2**63 - 1)]


def odd_values(rng: random.Random, e: Entry) -> str:
    """Extreme or ill-typed replacement text for a value (flow YAML, so it fits anywhere). A
    number mostly gets another number: a type error stops at the reader, an extreme one goes on
    into the simulation and the filter."""
    if is_number(str(e.value.value)) and rng.random() < 0.7:
        return rng.choice(NUMERIC_EXTREMES)
    choices = NUMERIC_EXTREMES + [
        "''", "~", "true", "[1, 2, 3]", "[]", "{a: 1}", "{}", "x" * 300, "uav\udcff", "\udcff",
        "A" * rng.choice([10_000, 1_000_000])]
    if e.key is not None and e.key.value == "name":
        choices += ["n" * 300, "UAV-1", "lead", "uav1"]
    return rng.choice(choices)


def mut_replace(rng, text, ents):
    cands = [e for e in ents if single_line(e.value)]
    if not cands:
        return None
    e = rng.choice(cands)
    new = odd_values(rng, e)
    s, t = e.value.start_mark.index, e.value.end_mark.index
    return (text[:s] + new + text[t:],
            f"replace {e.path} (line {e.value.start_mark.line + 1}) = {shorten(text[s:t], 30)} "
            f"with {shorten(new)}")


def keyed_entry(rng, ents):
    """A random mapping entry (one with a key), or None when there is none."""
    cands = [e for e in ents if e.key is not None]
    return rng.choice(cands) if cands else None


def mut_delete(rng, text, ents):
    e = keyed_entry(rng, ents)
    if e is None:
        return None
    desc = f"delete key {e.path} (line {e.key.start_mark.line + 1})"
    if e.parent.flow_style:
        return delete_flow_pair(text, e), desc
    lines = text.splitlines(keepends=True)
    first = e.key.start_mark.line
    if lines[first][:e.key.start_mark.column].strip():  # "- key: v": keep the dash, drop the pair
        end = block_extent(lines, e)
        head = lines[first][:e.key.start_mark.column].rstrip() + "\n"
        return "".join(lines[:first] + [head] + lines[end:]), desc
    return "".join(lines[:first] + lines[block_extent(lines, e):]), desc


def delete_flow_pair(text: str, e: Entry) -> str:
    s, t = e.key.start_mark.index, e.value.end_mark.index
    after = re.match(r"\s*,\s*", text[t:])
    if after:
        return text[:s] + text[t + after.end():]
    before = re.search(r",\s*$", text[:s])
    return text[:before.start() if before else s] + text[t:]


def entry_text(lines: list, e: Entry) -> tuple:
    """(lines of a block entry with its key at its own column, index of the line after it)."""
    first, col = e.key.start_mark.line, e.key.start_mark.column
    end = block_extent(lines, e) if not single_line(e.value) else first + 1
    body = [" " * col + lines[first][col:]] + lines[first + 1:end]
    if not body[-1].endswith("\n"):
        body[-1] += "\n"
    return body, end


def mut_duplicate(rng, text, ents):
    e = keyed_entry(rng, ents)
    if e is None:
        return None
    desc = f"duplicate key {e.path} (line {e.key.start_mark.line + 1})"
    if e.parent.flow_style:
        t = e.value.end_mark.index
        return text[:t] + ", " + text[e.key.start_mark.index:t] + text[t:], desc
    lines = text.splitlines(keepends=True)
    if not lines[-1].endswith("\n"):
        lines[-1] += "\n"
    body, end = entry_text(lines, e)
    return "".join(lines[:end] + body + lines[end:]), desc


def unknown_key(rng, ents) -> str:
    """A key no reader knows: a near miss of a real one (the reader's "did you mean") or not."""
    real = [str(e.key.value) for e in ents if e.key is not None and len(str(e.key.value)) > 2]
    if real and rng.random() < 0.5:
        k = rng.choice(real)
        i = rng.randrange(len(k) - 1)
        return k[:i] + k[i + 1] + k[i] + k[i + 2:] if rng.random() < 0.5 else k[:i] + k[i + 1:]
    return rng.choice(["zz_unknown", "Name", "k" * 300, "x y", "<<", "'1'"])


def mut_unknown(rng, text, ents):
    e = keyed_entry(rng, ents)
    if e is None:
        return None
    key = unknown_key(rng, ents)
    desc = f"add unknown key {shorten(key)} next to {e.path}"
    if e.parent.flow_style:
        t = e.value.end_mark.index
        return text[:t] + f", {key}: 1" + text[t:], desc
    lines = text.splitlines(keepends=True)
    if not lines[-1].endswith("\n"):
        lines[-1] += "\n"
    _, end = entry_text(lines, e)
    new = " " * e.key.start_mark.column + f"{key}: 1\n"
    return "".join(lines[:end] + [new] + lines[end:]), desc


STRUCTURAL = [mut_replace, mut_replace, mut_replace, mut_delete, mut_duplicate, mut_unknown]


# ---------------------------------------------------------------------------------------------
# Text mutations: work on any bytes, YAML or not.

def mut_truncate(rng, text):
    data = encode(text)
    n = rng.randrange(len(data)) if data else 0
    return decode(data[:n]), f"truncate at byte {n} of {len(data)}"


def mut_insert_bytes(rng, text):
    data = encode(text)
    pos = rng.randint(0, len(data))
    junk = rng.randbytes(rng.randint(1, 16))
    return decode(data[:pos] + junk + data[pos:]), f"insert bytes {junk.hex()} at byte {pos}"


def mut_indent(rng, text):
    lines = text.splitlines(keepends=True)
    cands = [i for i, l in enumerate(lines) if l.strip()]
    if not cands:
        return None
    i = rng.choice(cands)
    body = lines[i].lstrip(" ")
    old = indent_of(lines[i])
    new = rng.choice([max(0, old - rng.randint(1, 4)), old + rng.randint(1, 4), -1])
    lines[i] = ("\t" + body) if new < 0 else (" " * new + body)
    how = "a tab" if new < 0 else f"{new} spaces"
    return "".join(lines), f"indent line {i + 1} with {how} (was {old})"


def mut_swap(rng, text):
    lines = text.splitlines(keepends=True)
    if len(lines) < 2:
        return None
    if not lines[-1].endswith("\n"):
        lines[-1] += "\n"
    i, j = sorted(rng.sample(range(len(lines)), 2))
    lines[i], lines[j] = lines[j], lines[i]
    return "".join(lines), f"swap lines {i + 1} and {j + 1}"


TEXTUAL = [mut_truncate, mut_insert_bytes, mut_indent, mut_swap]


def mutate_once(rng: random.Random, text: str) -> tuple:
    """One mutation: mostly structural while the text still parses (a reader's checks are the
    target; yaml-cpp's own parse errors are the less interesting case), else a text one."""
    root = compose(text)
    ents = entries(root) if root is not None else []
    if ents and rng.random() < 0.75:
        result = rng.choice(STRUCTURAL)(rng, text, ents)
        if result:
            return result
    for _ in range(10):
        result = rng.choice(TEXTUAL)(rng, text)
        if result:
            return result
    return text, "no mutation applied"


def scenario_mutant(seed: int, corpus: list) -> tuple:
    """(source scene, mutant bytes, description) for one seed."""
    rng = random.Random(seed)
    src = rng.choice(corpus)
    text = decode(src.read_bytes())
    steps = []
    for _ in range(rng.randint(1, 3)):
        text, desc = mutate_once(rng, text)
        steps.append(desc)
    return src, encode(text), "; ".join(steps)


# ---------------------------------------------------------------------------------------------
# Dataset corruptions: each takes (rng, dataset copy root) and damages one thing in place,
# returning a description (paths relative to the root).

def files(root: Path, pattern: str) -> list:
    return sorted(root.rglob(pattern))


def rel(root: Path, p: Path) -> str:
    return str(p.relative_to(root))


def png_chunk(kind: bytes, body: bytes) -> bytes:
    return len(body).to_bytes(4, "big") + kind + body + zlib.crc32(kind + body).to_bytes(4, "big")


def cor_png_truncate(rng, root):
    p = rng.choice(files(root, "*.png"))
    data = p.read_bytes()
    n = rng.choice([0, 4, 8, 20, 33, rng.randrange(33, len(data))])
    p.write_bytes(data[:n])
    return f"truncate {rel(root, p)} to {n} of {len(data)} bytes"


def cor_png_flip(rng, root):
    """Flips bytes after the IHDR chunk: the header reads fine, the pixels do not."""
    p = rng.choice(files(root, "*.png"))
    data = bytearray(p.read_bytes())
    where = sorted(rng.sample(range(33, len(data)), min(rng.choice([1, 8, 64]), len(data) - 33)))
    for i in where:
        data[i] ^= 1 << rng.randrange(8)
    p.write_bytes(bytes(data))
    return f"flip {len(where)} bits after the header of {rel(root, p)} (first at byte {where[0]})"


def cor_png_body(rng, root):
    """A valid signature and IHDR followed by a broken IDAT or by nothing."""
    p = rng.choice(files(root, "*.png"))
    data = p.read_bytes()
    tail = rng.choice([b"", png_chunk(b"IDAT", rng.randbytes(64)), png_chunk(b"IEND", b"")])
    p.write_bytes(data[:33] + tail)
    return f"keep the header of {rel(root, p)}, body {tail[4:8].decode() or 'none'} (garbage)"


def cor_png_ihdr(rng, root):
    """Another width or height in the IHDR, with a correct CRC so decoders believe it."""
    p = rng.choice(files(root, "*.png"))
    data = bytearray(p.read_bytes())
    field = rng.choice([16, 20])
    value = rng.choice([0, 1, 999, 1001, 2**31 - 1, 65535])
    data[field:field + 4] = value.to_bytes(4, "big")
    data[29:33] = zlib.crc32(bytes(data[12:29])).to_bytes(4, "big")
    p.write_bytes(bytes(data))
    return f"set the IHDR {'width' if field == 16 else 'height'} of {rel(root, p)} to {value}"


def cor_frame_delete(rng, root):
    p = rng.choice(files(root, "*.png"))
    p.unlink()
    return f"delete {rel(root, p)}"


def csv_line_edit(rng, fields: list, prev_stamp: str) -> tuple:
    """(new line, what) for one data row's fields."""
    i = rng.randrange(1, len(fields)) if len(fields) > 1 else 0
    ops = {
        "empty": lambda: "",
        "truncated": lambda: ",".join(fields)[:rng.randrange(1, len(",".join(fields)))],
        "nan": lambda: ",".join(fields[:i] + ["nan"] + fields[i + 1:]),
        "1e308": lambda: ",".join(fields[:i] + ["1e308"] + fields[i + 1:]),
        "-inf": lambda: ",".join(fields[:i] + ["-inf"] + fields[i + 1:]),
        "text": lambda: ",".join(fields[:i] + ["abc"] + fields[i + 1:]),
        "blank field": lambda: ",".join(fields[:i] + [""] + fields[i + 1:]),
        "missing column": lambda: ",".join(fields[:-1]),
        "extra column": lambda: ",".join(fields + ["0"]),
        "unsorted time stamp": lambda: ",".join([prev_stamp] + fields[1:]),
        "huge time stamp": lambda: ",".join(["99999999999999999999"] + fields[1:]),
        "negative time stamp": lambda: ",".join(["-1"] + fields[1:]),
        "non-UTF-8": lambda: ",".join(fields) + "\udcff",
    }
    what = rng.choice(sorted(ops))
    where = f" (column {i + 1})" if what in ("nan", "1e308", "-inf", "text", "blank field") else ""
    return ops[what](), what + where


def cor_csv_line(rng, root):
    p = rng.choice(files(root, "*.csv"))
    lines = decode(p.read_bytes()).splitlines()
    rows = [k for k, l in enumerate(lines) if l and not l.startswith("#")]
    if not rows:
        return cor_csv_file(rng, root)
    k = rng.choice(rows)
    prev = lines[rows[-1]].split(",")[0] if k == rows[0] else lines[rows[0]].split(",")[0]
    lines[k], what = csv_line_edit(rng, lines[k].split(","), prev)
    p.write_bytes(encode("\n".join(lines) + "\n"))
    return f"{what} on line {k + 1} of {rel(root, p)}"


def cor_csv_file(rng, root):
    p = rng.choice(files(root, "*.csv"))
    data = p.read_bytes()
    what = rng.choice(["empty", "truncate", "no header", "duplicate rows"])
    if what == "empty":
        p.write_bytes(b"")
    elif what == "truncate":
        n = rng.randrange(len(data)) if data else 0
        p.write_bytes(data[:n])
        what = f"truncate at byte {n} of {len(data)}"
    elif what == "no header":
        p.write_bytes(b"\n".join(l for l in data.split(b"\n") if not l.startswith(b"#")))
    else:
        body = [l for l in data.split(b"\n") if l and not l.startswith(b"#")]
        p.write_bytes(data + b"\n".join(body) + b"\n")
    return f"{what}: {rel(root, p)}"


def cor_agent_dir(rng, root):
    agents = sorted(d for d in root.iterdir() if d.is_dir())
    d = rng.choice(agents)
    shutil.rmtree(d)
    return f"remove the agent directory {rel(root, d)}"


def yaml_edit(rng, p: Path, values: dict, root: Path) -> str:
    """Deletes a key of a small YAML file or gives one an odd value from `values`."""
    text = decode(p.read_bytes())
    ents = entries(compose(text)) if yaml is not None else []
    top = [e for e in ents if e.key is not None and "." not in e.path and "[" not in e.path]
    if not top:
        p.write_bytes(b"")
        return f"empty {rel(root, p)}"
    e = rng.choice(top)
    if rng.random() < 0.3:
        new, _ = mut_delete(random.Random(0), text, [e])
        p.write_bytes(encode(new))
        return f"remove key {e.path} from {rel(root, p)}"
    new = rng.choice(values.get(e.path, ["0", "-1", "nan", "''", "[]", "1e308"]))
    s, t = e.value.start_mark.index, e.value.end_mark.index
    if not single_line(e.value):  # a block value: replace its whole block
        lines = text.splitlines(keepends=True)
        end = block_extent(lines, e)
        head = lines[e.key.start_mark.line][:e.key.start_mark.column] + f"{e.path}: {new}\n"
        p.write_bytes(encode("".join(lines[:e.key.start_mark.line] + [head] + lines[end:])))
    else:
        p.write_bytes(encode(text[:s] + new + text[t:]))
    return f"set {e.path} = {shorten(new)} in {rel(root, p)} (was {shorten(text[s:t], 30)})"


DATASET_VALUES = {
    "format": ["other", "''"],
    "format_version": ["0", "1", "3", "999", "-1", "nan", "1.5"],
    "rate_hz": ["0", "-10", "nan", ".inf", "1e-300", "1e308"],
    "frames": ["0", "1", "-1", "1000000000", "3", "5"],
    "seed": ["-1", str(2**64), "nan", "abc"],
    "scenario": ["nonexistent", "''", "x" * 300],
    "variant": ["nonexistent", "''", "[]"],
    "agents": ["[]", "[lead]", "[lead, uav1, uav2, uav3]", "[uav2, uav1, lead]", "lead",
               "[lead, lead, uav1, uav2]", "['../lead', uav1, uav2]"],
}
SENSOR_VALUES = {
    "intrinsics": ["[0, 0, 500, 500]", "[.nan, 200.1, 500, 500]", "[-200, 200, 500, 500]",
                   "[1e308, 1e308, 500, 500]", "[200.1, 200.1, 500]"],
    "resolution": ["[999, 1000]", "[1000, 999]", "[0, 0]", "[-1000, 1000]", "[1e308, 1000]",
                   "[2147483648, 1000]", "[1000]"],
    "rate_hz": ["-10", "0", "nan", "1e-300"],
    "distortion_coefficients": ["[.nan, 0, 0, 0]", "[1e308, 0, 0, 0]", "[0, 0, 0, 0, 0]", "[0, 0, 0]"],
    "distortion_model": ["plumb_bob", "equidistant", "''"],
    "camera_model": ["omni", "''"],
    "T_BS": ["{cols: 4, rows: 4, data: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1]}",
             "{cols: 4, rows: 4, data: [.nan, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}",
             "{cols: 3, rows: 4, data: [1, 0, 0, 0, 1, 0, 0, 0, 1]}", "[1, 0, 0]"],
    "encoding": ["bgr8", "mono16", "rgb8", "''"],
    "gyroscope_noise_density": ["-1", "nan", "1e308"],
    "accelerometer_random_walk": ["-1", "nan"],
}


def cor_dataset_yaml(rng, root):
    return yaml_edit(rng, root / "dataset.yaml", DATASET_VALUES, root)


def cor_sensor_yaml(rng, root):
    return yaml_edit(rng, rng.choice(files(root, "sensor.yaml")), SENSOR_VALUES, root)


def cor_scenario_yaml(rng, root):
    """The scenario the replay reads: gone, or one scenario mutation."""
    p = root / "scenario.yaml"
    if rng.random() < 0.2:
        p.unlink()
        return "delete scenario.yaml"
    text, desc = mutate_once(rng, decode(p.read_bytes()))
    p.write_bytes(encode(text))
    return f"scenario.yaml: {desc}"


CORRUPTIONS = [cor_png_truncate, cor_png_flip, cor_png_body, cor_png_ihdr, cor_frame_delete,
               cor_csv_line, cor_csv_line, cor_csv_line, cor_csv_file, cor_agent_dir,
               cor_dataset_yaml, cor_dataset_yaml, cor_sensor_yaml, cor_sensor_yaml,
               cor_scenario_yaml]


# ---------------------------------------------------------------------------------------------
# Non-finite values in a results directory. By design metrics.json writes an undefined value as
# null and the CSVs write nan: a mean over no steps, the NEES at step 0, a landmark never removed.
# So a value counts only when (1) it is not under an object that says it covers nothing
# ("steps": 0 or "count": 0, or a per-phase entry of a phase with no steps) and (2) its
# signature (file, field path with agent names as <agent>, first item or a later one) does not
# occur in any unmutated input's run.

NONFINITE = re.compile(r"^[+-]?(nan(\(.*\))?|inf(inity)?)$", re.IGNORECASE)


def empty_phases(metrics: dict) -> set:
    """Indices of the phases no agent has a step in (table4 counts them)."""
    phases = (metrics.get("table4") or {}).get("phases") or []
    agents = [(p.get("agents") or {}).values() if isinstance(p, dict) else [] for p in phases]
    return {i for i, a in enumerate(agents) if all(map(no_steps, a))}


def no_steps(agent) -> bool:
    return isinstance(agent, dict) and agent.get("steps") == 0


# Ratios eval/metrics/metrics.hpp documents as NaN when their denominator, a sibling counter, is 0.
RATIO_DENOMINATOR = {"accepted_outlier_fraction": "accepted", "lead_detection_rate": "lead_in_view"}


def json_nonfinite(node, path: str, agents: set, skip: set, out: set) -> None:
    """Walks metrics.json: null or a NaN/Infinity token (never written by design) by path."""
    if isinstance(node, dict):
        if node.get("steps") == 0 or node.get("count") == 0:
            return
        for k, v in node.items():
            if v is None and node.get(RATIO_DENOMINATOR.get(k)) == 0:
                continue
            json_nonfinite(v, f"{path}.{'<agent>' if k in agents else k}", agents, skip, out)
    elif isinstance(node, list):
        per_phase = "per_phase" in path.rsplit(".", 1)[-1]
        for i, v in enumerate(node):
            if not (per_phase and i in skip):
                json_nonfinite(v, path + ("[0]" if i == 0 else "[]"), agents, skip, out)
    elif node is None:
        out.add(path)
    elif isinstance(node, float) and not math.isfinite(node):
        out.add(path + " (token)")


def csv_nonfinite(p: Path, agents: set, out: set) -> None:
    """NaN/inf fields by file, column name (a '#' or non-numeric first line) and row."""
    lines = decode(p.read_bytes()).splitlines()
    header = []
    if lines and (lines[0].startswith("#") or not all(is_number(f) for f in lines[0].split(","))):
        header = [h.strip().lstrip("# ") for h in lines.pop(0).split(",")]
    if agents:  # "uav1_nees_p" and "scout_nees_p" are the same field
        prefix = re.compile(r"^(" + "|".join(map(re.escape, agents)) + r")_")
        header = [prefix.sub("<agent>_", h) for h in header]
    for row, line in enumerate(lines):
        for i, f in enumerate(line.split(",")):
            if NONFINITE.match(f.strip()):
                col = header[i] if i < len(header) else str(i)
                out.add(f"{p.name}:{col}:{'first row' if row == 0 else 'later rows'}")


def is_number(f: str) -> bool:
    """Numbers and NaN/inf tokens alike (float() reads both)."""
    try:
        float(f)
        return True
    except ValueError:
        return False


def output_nonfinite(out_dir: Path) -> set:
    """Signatures of the non-finite values of every results directory under out_dir (one per
    variant when a scenario has several)."""
    found = set()
    for mj in sorted(out_dir.rglob("metrics.json")):
        try:
            metrics = json.loads(mj.read_text(errors="replace"))
        except ValueError:
            found.add("metrics.json (not JSON)")
            continue
        agents = {a for a in metrics.get("agents", []) if isinstance(a, str)}
        json_nonfinite(metrics, "metrics.json", agents, empty_phases(metrics), found)
        for p in sorted(mj.parent.glob("*.csv")):
            csv_nonfinite(p, agents, found)
    return found


# ---------------------------------------------------------------------------------------------
# Running one case and judging it.

@dataclasses.dataclass
class Case:
    index: int
    kind: str        # scenario | dataset | check (a baseline mutant) | baseline (unmutated)
    seed: int
    argv: list = dataclasses.field(default_factory=list)
    input_path: Path = None
    description: str = ""
    source: str = ""  # the unmutated input it comes from (a scene's file name, or "dataset")
    prepare: object = None  # makes the input just before the run; returns the description


def memory_cap(limit: int):
    """preexec_fn: the address-space cap, set in the child between fork and exec (0: none, for a
    sanitized binary, whose shadow memory needs terabytes of address space)."""
    def apply():
        if limit > 0:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return apply


def execute(argv: list, stderr_path: Path, timeout: float, mem: int) -> dict:
    """Runs argv in a process group of its own; at the timeout the whole group is killed."""
    start = time.monotonic()
    with open(stderr_path, "wb") as err:
        proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=err, preexec_fn=memory_cap(mem), process_group=0)
        timed_out = False
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    rc = proc.returncode
    return {"exit": rc if rc >= 0 else None, "signal": -rc if rc < 0 else None,
            "timed_out": timed_out, "seconds": round(time.monotonic() - start, 2)}


def keep_short(path: Path) -> str:
    """Trims the stored stderr to its head and tail; returns the whole kept text."""
    text = path.read_bytes().decode("utf-8", "replace")
    if len(text) > 2 * STDERR_KEEP:
        text = text[:STDERR_KEEP] + "\n[... trimmed ...]\n" + text[-STDERR_KEEP:]
        path.write_text(text)
    return text


def leftovers(out_dir: Path, failed: bool) -> list:
    found = [p.name for p in out_dir.parent.iterdir()
             if ".partial-" in p.name or ".old-" in p.name]
    if failed and out_dir.exists():
        found.append(out_dir.name)
    return sorted(found)


def check_verdict(res: dict, err: str, case: Case, out_dir: Path) -> str:
    """`wingman check` on a baseline mutant: 0 and 1 are verdicts, with the report written; a
    refusal names the mutant and writes no report."""
    report = (out_dir / "junit.xml").exists()
    if res["timed_out"]:
        return "hang"
    if res["signal"]:
        return "signal"
    if res["exit"] in (0, 1):
        return "ok_ran" if report else "no_output"
    if res["exit"] != 2:
        return "exit_other"
    if report:
        return "leftover"
    return "ok_refused" if str(case.input_path) in err else "ok_refused_unnamed"


def verdict(res: dict, err: str, case: Case, out_dir: Path, allowed: set) -> str:
    """The first that applies, from the run's fate to its outputs."""
    if case.kind == "check":
        return check_verdict(res, err, case, out_dir)
    failed = res["exit"] not in (0, 2)
    if res["timed_out"]:
        return "hang"
    if failed and any(s in err for s in OOM_PATTERNS):
        return "oom"
    if res["signal"]:
        return "signal"
    if res["leftover"]:
        return "leftover"
    if res["exit"] == 1:
        return "exit1_bad_input"
    if failed:
        return "exit_other"
    if res["exit"] == 2:
        return "ok_refused" if str(case.input_path) in err else "ok_refused_unnamed"
    if not any(out_dir.rglob("metrics.json")):
        return "no_output"
    res["nonfinite"] = sorted(output_nonfinite(out_dir) - allowed)
    if case.kind == "baseline":  # its non-finite values are the by-design ones
        return "ok_ran"
    return "nonfinite_output" if res["nonfinite"] else "ok_ran"


def run_case(case: Case, work: Path, opts, allowed: set) -> dict:
    if case.prepare is not None:
        case.description = case.prepare()
    run_dir = work / "runs" / f"{case.index:04d}"
    shutil.rmtree(run_dir, ignore_errors=True)
    run_dir.mkdir(parents=True)
    out_dir = run_dir / "out"  # does not exist before the run
    if case.kind == "check":  # check writes reports, not a results directory
        out_dir.mkdir()
        argv = [str(a) for a in case.argv] + ["--junit", str(out_dir / "junit.xml")]
    else:
        argv = [str(a) for a in case.argv] + ["--out", str(out_dir)]
    err_path = work / "stderr" / f"{case.index:04d}.txt"
    res = execute(argv, err_path, opts.timeout, int(opts.mem_gib * 2**30))
    err = keep_short(err_path)
    res["leftover"] = [] if case.kind == "check" else leftovers(out_dir, res["exit"] != 0)
    res.update(kind=case.kind, index=case.index, seed=case.seed, mutation=case.description,
               source=case.source, argv=argv)
    res["verdict"] = verdict(res, err, case, out_dir, allowed)
    lines = [l for l in err.splitlines() if l.strip()]
    res["stderr_last"] = lines[-1][:300] if lines else ""
    if res["verdict"] in OK_VERDICTS:
        shutil.rmtree(run_dir, ignore_errors=True)  # only findings keep their outputs
    return res


# ---------------------------------------------------------------------------------------------
# Building the cases.

def is_rendered(text: str) -> bool:
    return re.search(r"^measurements:\s*rendered\b", text, re.MULTILINE) is not None


def run_argv(wingman: str, scene: Path, rendered: bool) -> list:
    # Rendered: two frames, enough to build the world and run the frontend; on llvmpipe one frame
    # of some valid worlds at MSAA 4 takes seconds (docs/reliability.md), which is not a hang.
    return [wingman, "run", scene, "--no-plots", "-q"] + (["--frames", "2"] if rendered else ["--duration", "2"])


def scenario_cases(opts, work: Path, corpus: list) -> list:
    """Writes mutants/NNNN.yaml for each seed; the mutants depend on --seed only."""
    cases = []
    (work / "mutants").mkdir(exist_ok=True)
    for i in range(opts.scenario_mutants):
        seed = opts.seed * 1_000_000 + i
        src, data, desc = scenario_mutant(seed, corpus)
        path = work / "mutants" / f"{i:04d}.yaml"
        path.write_bytes(data)
        argv = run_argv(opts.wingman, path, is_rendered(decode(src.read_bytes())))
        cases.append(Case(i, "scenario", seed, argv, path, f"{src.name}: {desc}", src.name))
    return cases


def dataset_cases(opts, work: Path, dataset: Path, first: int) -> list:
    """One case per seed; its copy (corrupt/NNNN) is made and damaged only when it runs."""
    cases = []
    (work / "corrupt").mkdir(exist_ok=True)
    for j in range(opts.dataset_corruptions):
        i, seed = first + j, opts.seed * 1_000_000 + 500_000 + j
        copy = work / "corrupt" / f"{i:04d}"
        argv = [opts.wingman, "slam", copy, "--no-plots", "-q"]
        cases.append(Case(i, "dataset", seed, argv, copy, "", "dataset",
                          lambda seed=seed, copy=copy: corrupt_copy(seed, dataset, copy)))
    return cases


def check_cases(opts, work: Path, results: Path, first: int) -> list:
    """Mutants of the committed smoke baseline (mutants/check-NNNN.yaml), judged against a smoke run."""
    cases = []
    corpus = [REPO / "baselines" / "smoke.yaml"]
    for j in range(opts.baseline_mutants):
        i, seed = first + j, opts.seed * 1_000_000 + 700_000 + j
        _, data, desc = scenario_mutant(seed, corpus)
        path = work / "mutants" / f"check-{i:04d}.yaml"
        path.write_bytes(data)
        argv = [opts.wingman, "check", results, "--baseline", path]
        cases.append(Case(i, "check", seed, argv, path, f"smoke baseline: {desc}", "baselines/smoke.yaml"))
    return cases


def make_smoke_results(opts, work: Path) -> Path:
    """The smoke run the baseline mutants are checked against, made once per work directory."""
    res = work / "smoke_results"
    if not (res / "multi" / "metrics.json").exists():
        shutil.rmtree(res, ignore_errors=True)
        subprocess.run([opts.wingman, "run", str(REPO / "scenes" / "smoke.yaml"), "--out", str(res),
                        "--no-plots", "-q"], check=True, timeout=600)
    return res


def corrupt_copy(seed: int, dataset: Path, copy: Path) -> str:
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(dataset, copy)
    rng = random.Random(seed)
    return rng.choice(CORRUPTIONS)(rng, copy)


def baseline_cases(opts, dataset, first: int) -> list:
    """Unmutated inputs, run the same way: what they leave non-finite is by design. The
    writers are the same for every scene, so the cheapest scene stands for the synthetic ones
    and the dataset's replay for the rendered pipeline."""
    scene = REPO / "scenes" / "smoke.yaml"
    cases = [Case(first, "baseline", 0, run_argv(opts.wingman, scene, False), scene,
                  f"unmutated {scene.name}", scene.name)]
    if dataset is not None:
        argv = [opts.wingman, "slam", dataset, "--no-plots", "-q"]
        cases.append(Case(first + 1, "baseline", 0, argv, dataset, "unmutated dataset", "dataset"))
    return cases


def make_dataset(opts, work: Path) -> Path:
    """The small rendered dataset the corruptions copy, made once per work directory."""
    if opts.dataset:
        return Path(opts.dataset).resolve()
    ds = work / "dataset"
    if (ds / "dataset.yaml").exists():
        return ds
    shutil.rmtree(ds, ignore_errors=True)
    argv = [opts.wingman, "render", str(REPO / "scenes" / "rendered_smoke.yaml"), "--out", str(ds),
            "--frames", "4", "-q"]
    subprocess.run(argv, check=True, timeout=1800)
    return ds


# ---------------------------------------------------------------------------------------------
# Running everything and reporting.

class Runner:
    """Runs cases on a thread pool until the time budget is spent, writing outcomes.jsonl as
    each finishes (a stopped fuzzer keeps what it has)."""

    def __init__(self, opts, work: Path, deadline: float):
        self.opts, self.work, self.deadline = opts, work, deadline
        self.lock = threading.Lock()
        self.log = open(work / "outcomes.jsonl", "w")

    def one(self, case: Case, allowed: set):
        if time.monotonic() > self.deadline:
            return None
        try:
            res = run_case(case, self.work, self.opts, allowed)
        except Exception:  # one bad case must not end the others; it still counts
            traceback.print_exc()
            res = {"kind": case.kind, "index": case.index, "seed": case.seed, "exit": None,
                   "signal": None, "seconds": 0, "mutation": case.description, "leftover": [],
                   "verdict": "harness_error", "stderr_last": "", "source": case.source}
        with self.lock:
            self.log.write(json.dumps(res, default=str) + "\n")
            self.log.flush()
            print(f"[{case.index:04d}] {case.kind:8s} {res['verdict']:18s} {res['seconds']:6.1f}s "
                  f"{ascii(case.description[:100])[1:-1]}", flush=True)
        return res

    def all(self, cases: list, allowed: set) -> list:
        with concurrent.futures.ThreadPoolExecutor(self.opts.jobs) as pool:
            futures = [pool.submit(self.one, c, allowed) for c in cases]
            return [f.result() for f in futures if f.result() is not None]


def summary(results: list, skipped: int) -> str:
    if not results:
        return f"No run finished; {skipped} case(s) not started (the time budget ran out)."
    kinds = sorted({r["kind"] for r in results})
    verdicts = sorted({r["verdict"] for r in results}, key=lambda v: (v not in OK_VERDICTS, v))
    rows = ["| verdict | " + " | ".join(kinds) + " |", "|---|" + "---|" * len(kinds)]
    for v in verdicts:
        counts = [sum(1 for r in results if r["kind"] == k and r["verdict"] == v) for k in kinds]
        rows.append(f"| {v} | " + " | ".join(map(str, counts)) + " |")
    totals = [str(sum(r["kind"] == k for r in results)) for k in kinds]
    rows.append("| total | " + " | ".join(totals) + " |")
    if skipped:
        rows.append(f"\n{skipped} case(s) not started: the time budget ran out.")
    return "\n".join(rows)


def findings_text(findings: list) -> str:
    out = [f"\n{len(findings)} finding(s)" + (", the first 20:" if len(findings) > 20 else ":")]
    for r in findings[:20]:
        extra = f" new non-finite: {', '.join(r['nonfinite'][:4])}" if r.get("nonfinite") else ""
        extra += f" leftover: {', '.join(r['leftover'])}" if r["leftover"] else ""
        out.append(f"- [{r['index']:04d}] {r['verdict']} ({r['kind']}, seed {r['seed']}, exit "
                   f"{r['exit']}, signal {r['signal']}, {r['seconds']}s) {r['mutation']}{extra}\n"
                   f"    stderr: {r['stderr_last']}")
    return "\n".join(out)


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--wingman", required=True, help="the wingman binary")
    ap.add_argument("--workdir", required=True, help="mutants, outcomes and kept stderr go here")
    ap.add_argument("--scenario-mutants", type=int, default=50)
    ap.add_argument("--dataset-corruptions", type=int, default=20)
    ap.add_argument("--baseline-mutants", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--time-budget", type=float, default=math.inf,
                    help="seconds after which no new run starts")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=60, help="seconds per run")
    ap.add_argument("--mem-gib", type=float, default=4, help="address-space cap per run, GiB (0: none)")
    ap.add_argument("--dataset", help="dataset to corrupt (default: rendered once into WORKDIR)")
    opts = ap.parse_args(argv)
    opts.wingman = str(Path(opts.wingman).resolve())
    return opts


def main(argv=None) -> int:
    opts = parse_args(argv)
    start = time.monotonic()
    work = Path(opts.workdir).resolve()
    work.mkdir(parents=True, exist_ok=True)
    (work / "stderr").mkdir(exist_ok=True)
    corpus = sorted((REPO / "scenes").glob("*.yaml"))
    cases = scenario_cases(opts, work, corpus)
    try:
        dataset = make_dataset(opts, work) if opts.dataset_corruptions > 0 else None
    except (subprocess.SubprocessError, OSError) as e:
        print(f"error: cannot make the dataset to corrupt: {e}", file=sys.stderr)
        return 2
    if dataset is not None:
        cases += dataset_cases(opts, work, dataset, len(cases))
    if opts.baseline_mutants > 0:
        try:
            cases += check_cases(opts, work, make_smoke_results(opts, work), len(cases))
        except (subprocess.SubprocessError, OSError) as e:
            print(f"error: cannot make the smoke results to check against: {e}", file=sys.stderr)
            return 2
    runner = Runner(opts, work, start + opts.time_budget)
    base = runner.all(baseline_cases(opts, dataset, len(cases)), set())
    allowed = set().union(*(r.get("nonfinite", []) for r in base))
    results = runner.all(cases, allowed)
    runner.log.close()
    for r in base:
        if r["verdict"] != "ok_ran":
            print(f"warning: the unmutated {r['source']} gives {r['verdict']}: {r['stderr_last']}")
    print("non-finite by design (in the unmutated runs): " + (", ".join(sorted(allowed)) or "none"))
    findings = [r for r in results if r["verdict"] not in OK_VERDICTS]
    print(summary(results, len(cases) - len(results)))
    if findings:
        print(findings_text(findings))
    keep = {r["index"] for r in findings}  # a finding's damaged copy stays, to be rerun
    for c in cases:
        if c.kind == "dataset" and c.index not in keep:
            shutil.rmtree(c.input_path, ignore_errors=True)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
