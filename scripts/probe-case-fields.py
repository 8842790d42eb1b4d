#!/usr/bin/env python3
"""Probe every case field through `flocsim case check` (which reads a case as `flocsim run`
does and runs nothing): each field with a wrong type, out of range, NaN, and in a scene that
does not use it. Counts the answers that are good (refused with exit 2 naming the field, the
value as given and what is allowed; or, for a field a scene does not use, refused or warned
naming the field and the scene) against the bad ones, and lists the bad ones.

  scripts/probe-case-fields.py [FLOCSIM]     (default build/release/apps/flocsim)
"""
import json
import os
import re
import subprocess
import sys
import tempfile

FLOCSIM = sys.argv[1] if len(sys.argv) > 1 else "build/release/apps/flocsim"
SCENES = ["suspension", "fixed-array", "single-sphere", "granular", "fluid"]


def run(*args, text=None):
    if text is not None:
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
            f.write(text)
        args = [*args, f.name]
    p = subprocess.run([FLOCSIM, *args], capture_output=True, text=True)
    if text is not None:
        os.unlink(f.name)
    return p.returncode, p.stdout, p.stderr


def valid_case(scene):
    if scene == "fluid":
        return {"scene": "fluid", "fluid": {"size": [8, 8, 8], "viscosity": 0.1}}
    c = {"scene": scene, "fidelity": "draft"}
    if scene != "single-sphere":
        c["phi"] = 0.1
    return c


def put(doc, path, value):
    parts = path.split(".")
    for p in parts[:-1]:
        doc = doc.setdefault(p, {})
    doc[parts[-1]] = value


def leaves(properties, prefix=""):
    for name, s in properties.items():
        path = prefix + name
        if s.get("type") == "object" and "properties" in s:
            yield from leaves(s["properties"], path + ".")
        elif s.get("type") != "object":
            yield path, s


def scenes_of(path):
    code, out, _ = run("case", "explain", path)
    m = re.search(r"scene: (.*?)(?: \(elsewhere: (\w+)\))?$", out, re.M)
    used = re.findall(r'"([^"]+)"', m.group(1)) if m else SCENES
    return used, (m.group(2) if m and m.group(2) else None)


def probes(path, schema):
    """(kind, value as JSON text, value as the refusal must show it)"""
    t = schema.get("type")
    if "enum" in schema:
        yield "wrong type", "12", "12"
        yield "out of range", '"no-such-choice"', '"no-such-choice"'
    elif t in ("number", "integer"):
        yield "wrong type", '"abc"', '"abc"'
        if "maximum" in schema or "exclusiveMaximum" in schema:
            top = schema.get("maximum", schema.get("exclusiveMaximum"))
            v = int(top) + 1 if t == "integer" else top + max(1.0, abs(top)) * 1e-7
            text = json.dumps(v)
        else:
            low = schema.get("minimum", schema.get("exclusiveMinimum", 0))
            v = int(low) - 1 if t == "integer" else low - max(1.0, abs(low)) * 1e-7
            text = json.dumps(v)
        yield "out of range", text, text
        yield "NaN", "NaN", None
    elif t == "array":
        yield "wrong type", '"x"', '"x"'
        yield "out of range", "[1]", "[1]"
        yield "NaN", "[NaN, 1, 1]", None
    elif t == "string":
        yield "wrong type", "12", "12"
    elif t == "boolean":
        yield "wrong type", "3", "3"


def main():
    code, out, _ = run("case", "schema")
    schema = json.loads(out)
    good = bad = 0
    bad_lines = []
    counts = {}
    for path, s in leaves(schema["properties"]):
        if path == "scene":
            continue
        used, elsewhere = scenes_of(path)
        scene = used[0]
        cases = [(k, t, shown, scene) for k, t, shown in probes(path, s)]
        unused = [x for x in SCENES if x not in used]
        if unused:
            value = json.dumps(s.get("default", s.get("enum", [1])[0] if "enum" in s else
                                     {"number": 0.5, "integer": 1, "string": "x",
                                      "boolean": True, "array": [8, 8, 8]}.get(s.get("type"), 1)))
            cases.append(("unused scene", value, None, unused[0]))
        for kind, text, shown, sc in cases:
            doc = valid_case(sc)
            put(doc, path, "@@")
            body = json.dumps(doc).replace('"@@"', text)
            code, out, err = run("case", "check", text=body)
            if kind == "unused scene":
                # refused naming the field, or warned about naming it or the object
                # it sits in (whose given value then names it)
                leaf = path.split(".")[-1]
                warned = any(line.startswith("flocsim case check: warning: ") and sc in line
                             and leaf in line and path.startswith(line.split(": ")[2])
                             for line in err.splitlines())
                ok = (code == 2 and path in err and sc in err) or (code == 0 and warned)
            else:
                ok = code == 2 and path.split(".")[-1] in err and \
                    (shown is None or shown in err)
            counts.setdefault(kind, [0, 0])[0 if ok else 1] += 1
            if ok:
                good += 1
            else:
                bad += 1
                bad_lines.append(f"BAD {kind:13s} {path} = {text} (scene {sc}): exit {code}: "
                                 f"{err.strip()[:200]}")
    for line in bad_lines:
        print(line)
    for kind, (g, b) in counts.items():
        print(f"{kind:13s} good {g:3d}  bad {b:3d}")
    print(f"total: {good + bad} probes, {good} good, {bad} bad")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
