#!/usr/bin/env python3
"""The JSON Schemas of case and sweep files (schemas/), held to flocsim.

  check_schemas.py FLOCSIM SOURCE_DIR --export   the shipped schemas are what
                                                 `flocsim case schema [--sweep]` prints
  check_schemas.py FLOCSIM SOURCE_DIR            every shipped case, sweep and grid point
                                                 validates; every probe of
                                                 tests/case/schema_probes.json (cases and
                                                 sweeps flocsim refuses) fails

The second needs python3-jsonschema (scripts/install-deps.sh installs it); without
it the test exits 77, which CTest reports as skipped.
"""
import copy
import glob
import itertools
import json
import os
import subprocess
import sys


def export(flocsim, *args):
    return subprocess.run([flocsim, "case", "schema", *args], check=True,
                          capture_output=True, text=True).stdout


def check_export(flocsim, source):
    bad = 0
    for name, args in (("case.schema.json", []), ("sweep.schema.json", ["--sweep"])):
        with open(os.path.join(source, "schemas", name)) as f:
            shipped = f.read()
        if shipped != export(flocsim, *args):
            print(f"schemas/{name} differs from `flocsim case schema {' '.join(args)}`; "
                  f"regenerate it with: flocsim case schema {' '.join(args)} > schemas/{name}")
            bad += 1
    return bad


def put(document, path, value):
    parts = path.split(".")
    for p in parts[:-1]:
        document = document.setdefault(p, {})
    document[parts[-1]] = value


def grid_points(sweep):
    base = copy.deepcopy(sweep["base"])
    if "fidelity" in sweep:
        base["fidelity"] = sweep["fidelity"]
    axes = list(sweep["axes"].items())
    for values in itertools.product(*(v for _, v in axes)):
        point = copy.deepcopy(base)
        for (path, _), value in zip(axes, values):
            put(point, path, value)
        yield point


def check_validation(source):
    try:
        import jsonschema
    except ImportError:
        print("python3-jsonschema is not installed (scripts/install-deps.sh installs it): skipped")
        return 77
    schemas = {}
    for name in ("case", "sweep"):
        with open(os.path.join(source, "schemas", f"{name}.schema.json")) as f:
            schemas[name] = json.load(f)
        jsonschema.Draft202012Validator.check_schema(schemas[name])
    case = jsonschema.Draft202012Validator(schemas["case"])
    sweep = jsonschema.Draft202012Validator(schemas["sweep"])
    bad = checked = 0

    def expect(validator, document, valid, what):
        nonlocal bad, checked
        checked += 1
        errors = list(validator.iter_errors(document))
        if valid and errors:
            bad += 1
            print(f"{what}: should validate, does not: {errors[0].message} at "
                  f"{'/'.join(map(str, errors[0].absolute_path))}")
        if not valid and not errors:
            bad += 1
            print(f"{what}: flocsim refuses it, the schema accepts it")

    for path in sorted(glob.glob(os.path.join(source, "examples", "*.json"))):
        with open(path) as f:
            expect(case, json.load(f), True, os.path.relpath(path, source))
    for path in sorted(glob.glob(os.path.join(source, "sweeps", "**", "*.json"), recursive=True)):
        with open(path) as f:
            s = json.load(f)
        what = os.path.relpath(path, source)
        expect(sweep, s, True, what)
        for i, point in enumerate(grid_points(s)):
            expect(case, point, True, f"{what}, grid point {i}")
    with open(os.path.join(source, "tests", "case", "schema_probes.json")) as f:
        probes = json.load(f)
    for p in probes["cases"]:
        expect(case, p["case"], False, f"probe case ({p['why']})")
    for p in probes["sweeps"]:
        expect(sweep, p["sweep"], False, f"probe sweep ({p['why']})")
    print(f"{checked} documents checked, {bad} wrong")
    return 1 if bad else 0


def main():
    flocsim, source = sys.argv[1], sys.argv[2]
    if "--export" in sys.argv[3:]:
        return 1 if check_export(flocsim, source) else 0
    return check_validation(source)


if __name__ == "__main__":
    sys.exit(main())
