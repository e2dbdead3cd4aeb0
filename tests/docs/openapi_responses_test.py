#!/usr/bin/env python3
"""The farm's real answers against docs/openapi.json.

farm_integration_test's coordinators record every answer they send (tessera-server
--record-responses, one JSON line each, into the directory given here; tests/CMakeLists.txt runs
it first). Each answer is matched to its operation by method and path; its status must be one the
operation describes, its content type one described for that status, and a JSON body must validate
against that content's schema, with no field the schema does not name. An answer on no described operation must be a described error
(unknown paths: 404 and the checks before routing) with the Error schema. The operations the
farm's tests must have exercised are listed below; a missing recording directory is a failure.

    python3 tests/docs/openapi_responses_test.py RESPONSES_DIR
"""
import glob
import json
import os
import re
import sys
import warnings

warnings.simplefilter("ignore", DeprecationWarning)  # RefResolver: the API of Debian 12's jsonschema
from jsonschema import Draft202012Validator, RefResolver  # noqa: E402
from jsonschema.exceptions import best_match  # noqa: E402


ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def closed(node):
    """The description with every object schema closed: the answers may carry no field it does not
    name. (The file leaves response objects open, so that clients accept fields added later.)"""
    if isinstance(node, dict):
        node = {k: closed(v) for k, v in node.items()}
        if "properties" in node and "additionalProperties" not in node:
            node["additionalProperties"] = False
        return node
    return [closed(v) for v in node] if isinstance(node, list) else node


SPEC = closed(json.load(open(os.path.join(ROOT, "docs", "openapi.json"), encoding="utf-8")))
# Statuses any request can get before it reaches a route (auth.cpp, http_admission.cpp; 408: a body
# that stopped arriving, connection_guard.cpp).
BEFORE_ROUTING = {"401", "404", "408", "411", "413"}
# What the farm's tests exercise at the least: the client's and the worker's whole round trip.
MUST_SEE = ["getHealth", "uploadScene", "submitJob", "listJobs", "getJobStatus", "getJobImage", "cancelJob",
            "registerWorker", "listWorkers", "leaseWork", "sendHeartbeat", "uploadResult", "signOffWorker",
            "getOpenApi"]

RESOLVER = RefResolver.from_schema(SPEC)


def resolve(node):
    while isinstance(node, dict) and "$ref" in node and node["$ref"].startswith("#/components/responses/"):
        node = SPEC["components"]["responses"][node["$ref"].rsplit("/", 1)[1]]
    return node


def path_regex(template, parameters):
    patterns = {p["name"]: p.get("schema", {}).get("pattern", "^[^/]+$") for p in parameters if p["in"] == "path"}
    out, pos = "", 0
    for m in re.finditer(r"\{([^}]+)\}", template):
        out += re.escape(template[pos:m.start()]) + "(?:" + patterns[m.group(1)].lstrip("^").rstrip("$") + ")"
        pos = m.end()
    return re.compile(out + re.escape(template[pos:]) + "$")


def operations():
    ops = []
    for template, item in SPEC["paths"].items():
        for method, op in item.items():
            if method == "parameters":
                continue
            params = item.get("parameters", []) + op.get("parameters", [])
            ops.append((method.upper(), path_regex(template, params), template, op))
    return ops


def media(content_type):
    return content_type.split(";")[0].strip().lower()


def check_body(record, response, where):
    """Problems of one answer against the response object described for its status."""
    content = response.get("content", {})
    body, ctype = record["body"], record["content_type"]
    if not ctype:
        return [] if not content or record["status"] == 204 else [f"{where}: no content type, but content is described"]
    described = {media(k): v for k, v in content.items()}
    entry = described.get(media(ctype)) or described.get(media(ctype).split("/")[0] + "/*") or described.get("*/*")
    if entry is None:
        return [f"{where}: content type {ctype} is not described (described: {sorted(described)})"]
    if media(ctype) != "application/json":
        return []
    try:
        value = json.loads(body)
    except ValueError as e:
        return [f"{where}: the JSON body does not parse: {e}"]
    validator = Draft202012Validator(entry.get("schema", {}), resolver=RESOLVER)
    error = best_match(validator.iter_errors(value))
    if error is None:
        return []
    while error.context:  # the branch of a oneOf/anyOf that came closest, not the whole body
        error = best_match(error.context)
    return [f"{where}: {error.message[:300]} at {'/'.join(str(p) for p in error.absolute_path) or 'the root'}"]


def check(record, ops, seen):
    method, path, status = record["method"], record["path"], str(record["status"])
    where = f"{method} {path} -> {status}"
    if method == "HEAD":
        return []
    matches = [(t, op) for m, rx, t, op in ops if m == method and rx.match(path)]
    if len(matches) > 1:
        return [f"{where}: matches {len(matches)} described operations"]
    if not matches:
        if status not in BEFORE_ROUTING and status != "400":
            return [f"{where}: no described operation, and not an error made before routing"]
        return check_body(record, {"content": {"application/json": {"schema": {"$ref": "#/components/schemas/Error"}}}}, where)
    template, op = matches[0]
    seen.add(op["operationId"])
    responses = op["responses"]
    response = responses.get(status) or responses.get(status[0] + "XX") or responses.get("default")
    if response is None:
        return [f"{where}: status {status} is not described for {op['operationId']} ({template})"]
    return check_body(record, resolve(response), where)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    files = sorted(glob.glob(os.path.join(sys.argv[1], "*.jsonl")))
    if not files:
        sys.exit(f"no recorded answers in {sys.argv[1]}: run farm_integration_test with TESSERA_RECORD_RESPONSES")
    ops = operations()
    seen, problems, count = set(), [], 0
    for name in files:
        with open(name, encoding="utf-8") as f:
            for number, line in enumerate(f, 1):
                if not line.strip():
                    continue
                count += 1
                for p in check(json.loads(line), ops, seen):
                    problems.append(f"{os.path.basename(name)}:{number}: {p}")
    unseen = [op for op in MUST_SEE if op not in seen]
    described = sorted(op["operationId"] for _, _, _, op in ops)
    print(f"{count} answers in {len(files)} files; operations seen: {len(seen)} of {len(described)}")
    print("not seen:", ", ".join(op for op in described if op not in seen) or "none")
    for p in problems[:40]:
        print("FAIL", p)
    if len(problems) > 40:
        print(f"... and {len(problems) - 40} more")
    if unseen:
        print("FAIL: the farm's tests did not exercise", ", ".join(unseen))
    sys.exit(1 if problems or unseen else 0)


if __name__ == "__main__":
    main()
