#!/usr/bin/env python3
"""The dashboard and `tessera` speak the API's names (docs/openapi.json).

- Dashboard (server/web/): every field it reads of a job (`job.X`), a worker (`w.X`) or the
  health answer (`h.X`) is a property of the schema it comes from; every state it styles or treats
  as live is a job or worker state of the description, and every such state has a style.
- `tessera submit --help`: every option is a field of a job request (dashes for underscores) or
  one of the client's own; a choice list ({a,b}) offers only values the field accepts ({on,off}
  for a boolean); the job states the CLI waits for are states of the description.

    python3 tests/docs/api_names_test.py TESSERA_BINARY
"""
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCHEMAS = json.load(open(os.path.join(ROOT, "docs", "openapi.json"), encoding="utf-8"))["components"]["schemas"]
# `tessera submit` options that are the client's, not fields of the job.
CLIENT_OPTIONS = {"help", "server", "token-file", "ca-file", "output", "wait", "force", "quiet", "D"}


def read(*parts):
    return open(os.path.join(ROOT, *parts), encoding="utf-8").read()


def props(*names):
    out = {}
    for n in names:
        out.update(SCHEMAS[n].get("properties", {}))
    return out


def enum(schema, prop):
    return set(SCHEMAS[schema]["properties"][prop].get("enum", []))


def types(schema):
    t = schema.get("type", [])
    return set(t if isinstance(t, list) else [t])


def dashboard_problems():
    app, css = read("server", "web", "app.js"), read("server", "web", "style.css")
    sources = {"job": props("JobStatus", "JobSummary"), "w": props("WorkerStatus", "WorkerShare"), "h": props("Health")}
    problems = []
    for var, fields in sources.items():
        for field in sorted(set(re.findall(r"\b" + var + r"\.([a-z_]+)\b", app))):
            if field not in fields:
                problems.append(f"app.js reads {var}.{field}, which the API does not send")
    states = enum("JobStatus", "state") | enum("JobSummary", "state") | enum("WorkerStatus", "state")
    styled = set(re.findall(r"\.state-([a-z_]+)", css))
    for s in sorted(styled - states):
        problems.append(f"style.css styles state '{s}', which is no job or worker state of the API")
    for s in sorted(states - styled):
        problems.append(f"state '{s}' of the API has no style in style.css")
    live = re.search(r"LIVE = new Set\(\[([^\]]*)\]\)", app)
    for s in re.findall(r"'([a-z_]+)'", live.group(1) if live else ""):
        if s not in states:
            problems.append(f"app.js counts '{s}' as live, which is no state of the API")
    if not live:
        problems.append("app.js: the set of live job states was not found")
    return problems


def cli_problems(tessera):
    help_text = subprocess.run([tessera, "submit", "--help"], capture_output=True, text=True, check=True).stdout
    fields = props("JobRequest")
    problems, seen = [], 0
    for m in re.finditer(r"^\s+(?:-\w,)?--?([A-Za-z][\w-]*)(?: ([A-Z]+)(?::(\{[^}]*\}))?)?", help_text, re.M):
        name, choices = m.group(1), m.group(3)
        if name in CLIENT_OPTIONS:
            continue
        seen += 1
        field = name.replace("-", "_")
        if field not in fields:
            problems.append(f"tessera submit --{name}: no job field '{field}' in the API")
            continue
        if not choices:
            continue
        values = choices.strip("{}").split(",")
        schema = fields[field]
        if "boolean" in types(schema) and set(values) == {"on", "off"}:
            continue
        allowed = set(schema.get("enum", []))
        for v in values:
            if v not in allowed:
                problems.append(f"tessera submit --{name} offers '{v}', which job field '{field}' does not accept")
    if seen < 10:
        problems.append(f"only {seen} job options found in `tessera submit --help`: has its format changed?")
    states = enum("JobStatus", "state") | set(SCHEMAS["JobStatus"]["properties"]["denoise_state"].get("enum", []))
    source = read("cli", "src", "submit_command.cpp")
    compared = re.findall(r'state[^;\n]{0,20}?[!=]=\s*"([a-z_]+)"', source)
    if not compared:
        problems.append("cli/src/submit_command.cpp: no comparison with a job state found")
    for s in sorted(set(compared) - states):
        problems.append(f"cli/src/submit_command.cpp waits for state '{s}', which is no state of the API")
    return problems


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    problems = dashboard_problems() + cli_problems(sys.argv[1])
    for p in problems:
        print("FAIL", p)
    print(f"{len(problems)} problems")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
