#!/usr/bin/env python3
"""Static checks of the container and Kubernetes files in docker/ (and docs/deploy.md).

No Docker engine or cluster is needed: the YAML is parsed and its structure checked (probes, ports,
selectors, secrets, volumes), the Dockerfile's instructions are checked against the repository, and
every --flag passed to tessera-server, tessera-worker or tessera anywhere in those files is checked
against the real programs' --help (paths from CTest). Exit 0 pass, 1 fail, 77 skip (PyYAML missing,
outside CI only).

usage: deploy_static_test.py --server BIN --worker BIN --cli BIN [--root DIR]
"""
import argparse
import json
import os
import re
import shlex
import subprocess
import sys
from urllib.parse import urlparse

try:
    import yaml
except ImportError:
    if os.environ.get("CI") == "true":
        print("FAIL: python3-yaml is missing (scripts/install-deps.sh installs it)")
        sys.exit(1)
    print("SKIP: python3-yaml is missing (scripts/install-deps.sh installs it)")
    sys.exit(77)

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from deploy_files import (PROGRAMS, Invocation, as_list, dockerignore_rules, effective,  # noqa: E402
                          flag_value, ignored, interpolate, listen_port, parse_dockerfile, parse_help,
                          shell_invocations)
from k8s_checks import check_kubernetes  # noqa: E402


class Checker:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def check(self, ok, what, detail=""):
        if ok:
            self.passed += 1
            print(f"ok    {what}")
        else:
            self.failed += 1
            print(f"FAIL  {what}" + (f": {detail}" if detail else ""))
        return ok


def run_help(cmd):
    out = subprocess.run(cmd + ["--help"], capture_output=True, text=True, timeout=30)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} --help exited {out.returncode}: {out.stderr}")
    return out.stdout


class FlagChecker:
    """Every --flag of an invocation must be one of its program's options, with a value if the
    option takes one; every REQUIRED option must be given."""

    def __init__(self, c, bins):
        self.c = c
        self.specs = {"tessera-server": parse_help(run_help([bins["tessera-server"]])),
                      "tessera-worker": parse_help(run_help([bins["tessera-worker"]]))}
        top = parse_help(run_help([bins["tessera"]]))
        self.subcommands = top.subcommands
        for sub in top.subcommands:
            self.specs["tessera " + sub] = parse_help(run_help([bins["tessera"], sub]))
        for name in ("tessera-server", "tessera-worker"):
            c.check(len(self.specs[name].options) >= 5, f"--help of {name} lists its options",
                    f"parsed {sorted(self.specs[name].options)}")
        c.check({"submit", "render"} <= set(self.subcommands), "--help of tessera lists its subcommands",
                f"parsed {self.subcommands}")
        self.checked = 0

    def check(self, inv: Invocation):
        key = inv.program
        args = list(inv.args)
        if key == "tessera":
            if not args or args[0] not in self.subcommands:
                self.c.check(False, f"{inv.where}: tessera subcommand", f"got {args[:1]}")
                return
            key = "tessera " + args.pop(0)
        spec = self.specs.get(key)
        if spec is None:
            self.c.check(False, f"{inv.where}: runs a Tessera program", f"runs {key!r}")
            return
        bad = []
        i = 0
        while i < len(args):
            a = args[i]
            if a.startswith("--"):
                name, eq, _ = a.partition("=")
                opt = spec.options.get(name)
                if opt is None:
                    bad.append(f"{name} is not an option of {key}")
                elif opt.takes_value and not eq:
                    if i + 1 >= len(args) or args[i + 1].startswith("--"):
                        bad.append(f"{name} needs a value")
                    i += 1
                elif not opt.takes_value and eq:
                    bad.append(f"{name} takes no value")
            i += 1
        for req in spec.required:
            if flag_value(args, req) is None:
                bad.append(f"required {req} missing")
        self.checked += 1
        self.c.check(not bad, f"{inv.where}: flags of `{key} {' '.join(args)}`", "; ".join(bad))


def load_yaml_files(c, root):
    docs = {}
    for dirpath, _, files in os.walk(os.path.join(root, "docker")):
        for f in sorted(files):
            if f.endswith((".yaml", ".yml")):
                path = os.path.join(dirpath, f)
                rel = os.path.relpath(path, root)
                try:
                    with open(path) as fh:
                        docs[rel] = [d for d in yaml.safe_load_all(fh) if d is not None]
                    c.check(bool(docs[rel]), f"{rel} parses as YAML")
                except yaml.YAMLError as e:
                    c.check(False, f"{rel} parses as YAML", str(e))
    return docs


def check_dockerfile(c, root, flags):
    path = os.path.join(root, "docker", "Dockerfile")
    if not c.check(os.path.isfile(path), "docker/Dockerfile exists"):
        return None
    df = parse_dockerfile(open(path).read())
    froms = [i.args.split()[0] for i in df.instructions if i.op == "FROM"]
    c.check(froms == ["debian:12", "debian:12-slim", "runtime", "runtime"],
            "Dockerfile: build on debian:12, runtime on debian:12-slim, then the image with the host's programs "
            "(target prebuilt) and the default image with the ones compiled", f"FROMs {froms}")
    text = open(path).read()
    c.check(text.rstrip().endswith("FROM runtime\nCOPY --from=build /out/ /usr/local/bin/"),
            "Dockerfile: the default (last) image copies the programs its build stage compiled")
    stages = df.stages()
    build_runs = " ".join(i.args for i in stages[0] if i.op == "RUN")
    final_runs = " ".join(i.args for i in stages[1] if i.op == "RUN")  # (the runtime stage the images share)
    c.check(re.search(r"scripts/install-deps\.sh\s+--build(\s|&|;|$)", build_runs) is not None,
            "Dockerfile: the build stage runs scripts/install-deps.sh --build (no test packages)")
    c.check("install-deps.sh --runtime" in final_runs, "Dockerfile: the runtime stage runs install-deps.sh --runtime")
    targets = re.search(r"--target\s+([\w\s-]+?)(?:&&|\\|$)", build_runs)
    c.check(targets is not None and {"tessera", "tessera-server", "tessera-worker"} <= set(targets.group(1).split()),
            "Dockerfile: builds tessera, tessera-server and tessera-worker", targets.group(1) if targets else "no --target")
    c.check("-DCMAKE_BUILD_TYPE=Release" in build_runs, "Dockerfile: a Release build")

    rules = dockerignore_rules(os.path.join(root, ".dockerignore"))
    c.check(bool(rules), ".dockerignore exists at the build context's root")
    for sample in ("build/CMakeCache.txt", "build-deploy/server/tessera-server", "out/demo.png", ".git/HEAD"):
        c.check(ignored(rules, sample), f".dockerignore excludes {sample.split('/')[0]}/")
    copied = set()
    whole_context = False
    for ins in df.instructions:
        if ins.op not in ("COPY", "ADD"):
            continue
        words = shlex.split(ins.args)
        if any(w.startswith("--from") for w in words):
            continue
        words = [w for w in words if not w.startswith("--")]
        for src in words[:-1]:
            if os.path.normpath(src) == ".":
                # The whole context: it holds what .dockerignore does not leave out.
                whole_context = True
                copied.update(e for e in os.listdir(root) if not ignored(rules, e))
                continue
            full = os.path.join(root, src)
            hidden = [src] if ignored(rules, os.path.normpath(src)) else []
            for dirpath, _, files in os.walk(full):
                hidden += [os.path.relpath(os.path.join(dirpath, f), root) for f in files
                           if ignored(rules, os.path.relpath(os.path.join(dirpath, f), root))]
            c.check(os.path.exists(full) and not hidden,
                    f"Dockerfile: COPY source {src} is in the repository, none of it in .dockerignore",
                    "missing" if not os.path.exists(full) else f"ignored: {hidden[:5]}")
            copied.add(os.path.normpath(src))
    top = open(os.path.join(root, "CMakeLists.txt")).read()
    subdirs = re.findall(r"add_subdirectory\((\w+)\)", top)
    needed = [d for d in subdirs if d != "tests"] + ["CMakeLists.txt"]
    c.check(all(d in copied for d in needed), "Dockerfile: copies every folder the top CMakeLists.txt adds",
            f"missing {[d for d in needed if d not in copied]}")
    if whole_context:
        hidden = [os.path.relpath(os.path.join(dirpath, f), root)
                  for d in needed if os.path.isdir(os.path.join(root, d))
                  for dirpath, _, files in os.walk(os.path.join(root, d)) for f in files
                  if ignored(rules, os.path.relpath(os.path.join(dirpath, f), root))]
        c.check(not hidden, "Dockerfile: .dockerignore leaves out no file of the folders the build adds",
                f"ignored: {hidden[:5]}")
    # Files outside those folders that their CMakeLists read (e.g. the API description the server
    # compiles in) must reach the build too.
    for d in needed:
        lists = os.path.join(root, d, "CMakeLists.txt") if os.path.isdir(os.path.join(root, d)) else None
        for ref in re.findall(r"\$\{PROJECT_SOURCE_DIR\}/([\w./-]+)", open(lists).read() if lists else ""):
            c.check(os.path.exists(os.path.join(root, ref)) and not ignored(rules, ref),
                    f"Dockerfile: {ref}, read by {d}/CMakeLists.txt, is in the build context")
    if "tests" not in copied:
        c.check("-DTESSERA_BUILD_TESTS=OFF" in build_runs, "Dockerfile: tests/ not copied, so TESSERA_BUILD_TESTS=OFF")

    final = {i.op: i for i in stages[1]}  # (the runtime stage: both images inherit its user, port and entrypoint)
    user = final.get("USER")
    c.check(user is not None and user.args.split(":")[0] not in ("root", "0"), "Dockerfile: runs as a non-root user")
    expose = final.get("EXPOSE")
    c.check(expose is not None and expose.args.split() == ["8080"], "Dockerfile: EXPOSE 8080")
    hc = final.get("HEALTHCHECK")
    c.check(hc is not None and "http://127.0.0.1:8080/healthz" in hc.args, "Dockerfile: HEALTHCHECK on /healthz:8080")
    entry = json.loads(final["ENTRYPOINT"].args) if "ENTRYPOINT" in final else []
    cmd = json.loads(final["CMD"].args) if "CMD" in final else []
    c.check(entry == ["tessera-server"], "Dockerfile: the entrypoint is tessera-server", str(entry))
    c.check(listen_port(cmd) == 8080 and flag_value(cmd, "--listen").startswith("0.0.0.0:"),
            "Dockerfile: the default command listens on 0.0.0.0:8080", str(cmd))
    if entry:
        flags.check(Invocation("Dockerfile ENTRYPOINT+CMD", os.path.basename(entry[0]), entry[1:] + cmd))
    for ins in df.instructions:
        if ins.op == "RUN":
            for inv in shell_invocations(ins.args, "Dockerfile RUN", flags.subcommands):
                flags.check(inv)
    if hc is not None and "curl" in hc.args:
        c.check("curl" in runtime_packages(root), "install-deps.sh --runtime installs curl (for the HEALTHCHECK)")
    return entry, cmd


def listed_packages(root, mode):
    out = subprocess.run(["bash", os.path.join(root, "scripts", "install-deps.sh"), mode],
                         capture_output=True, text=True, timeout=30)
    return set(out.stdout.split()) if out.returncode == 0 else set()


def runtime_packages(root):
    return listed_packages(root, "--list-runtime")


# Packages only the tests use: the image's build stage (install-deps.sh --build) must not install them.
TEST_ONLY = {"libgtest-dev", "libgmock-dev", "clang-tidy", "python3-yaml", "iproute2", "chromium", "chromium-driver",
             "python3-selenium", "podman", "podman-compose", "buildah", "runc", "debootstrap"}


def check_install_modes(c, root):
    full, build = listed_packages(root, "--list"), listed_packages(root, "--list-build")
    if not c.check(bool(full) and bool(build), "install-deps.sh --list and --list-build list packages"):
        return
    c.check(build <= full, "install-deps.sh: the default installs everything --build does",
            f"only in --build: {sorted(build - full)}")
    c.check(not build & TEST_ONLY, "install-deps.sh --build installs no test-only package",
            f"{sorted(build & TEST_ONLY)}")
    c.check({"build-essential", "cmake", "ninja-build"} <= build, "install-deps.sh --build installs a compiler, CMake and Ninja")
    demo = open(os.path.join(root, "scripts", "demo.sh")).read()
    c.check(re.search(r"^bash scripts/install-deps\.sh --build$", demo, re.M) is not None and
            "install-deps.sh\n" not in demo and not re.search(r"install-deps\.sh\s*$", demo, re.M),
            "scripts/demo.sh installs the build packages only (install-deps.sh --build: no browser, no container tools)")
    need = {"podman", "podman-compose", "debootstrap"}
    c.check(need <= full, "install-deps.sh (default, what CI runs) installs the container test's tools",
            f"missing {sorted(need - full)}")


def check_runtime_libraries(c, root, bins):
    """Every shared library the binaries link directly comes from a package that
    install-deps.sh --runtime installs (what the runtime image has)."""
    packages = runtime_packages(root)
    if not c.check(bool(packages), "install-deps.sh --list-runtime lists packages"):
        return
    if subprocess.run(["sh", "-c", "command -v dpkg-query && command -v readelf && command -v ldd"],
                      capture_output=True).returncode != 0:
        c.check(os.environ.get("CI") != "true", "dpkg, readelf and ldd present (Debian)",
                "cannot map libraries to packages")
        return
    linked = {}
    for name, binary in bins.items():
        needed = re.findall(r"\(NEEDED\).*\[(.+?)\]", subprocess.run(["readelf", "-d", binary],
                                                                      capture_output=True, text=True).stdout)
        resolved = dict(re.findall(r"^\s*(\S+) => (\S+)", subprocess.run(["ldd", binary], capture_output=True,
                                                                           text=True).stdout, re.M))
        linked[name] = {lib: resolved.get(lib) for lib in needed}

    def candidates(path):  # dpkg records /lib or /usr/lib, whichever the package ships (usrmerge)
        return {path, os.path.realpath(path), re.sub(r"^/usr/lib/", "/lib/", path), re.sub(r"^/lib/", "/usr/lib/", path)}

    paths = sorted({c for libs in linked.values() for p in libs.values() if p for c in candidates(p)})
    # One dpkg-query for every path; it exits 1 when some are not found, and lists the others.
    out = subprocess.run(["dpkg-query", "-S"] + paths, capture_output=True, text=True).stdout
    owner_of = {}
    for line in out.splitlines():
        pkgs, _, path = line.partition(": ")
        owner_of[path.strip()] = pkgs.split(",")[0].split(":")[0].strip()
    for name, libs in linked.items():
        missing = []
        for lib, path in libs.items():
            owner = next((owner_of[c] for c in candidates(path) if c in owner_of), None) if path else None
            if owner is None or owner not in packages:
                missing.append(f"{lib} ({owner or 'no package'})")
        c.check(bool(libs) and not missing, f"runtime packages cover every library {name} links",
                "not in install-deps.sh runtime_packages: " + ", ".join(missing))


def check_compose(c, docs, image, flags):
    doc = (docs.get("docker/compose.yaml") or [None])[0]
    if not c.check(isinstance(doc, dict) and "services" in doc, "docker/compose.yaml has services"):
        return
    doc = interpolate(doc)
    services = doc["services"]
    invs = {}
    for name, svc in services.items():
        entry, cmd = effective(as_list(svc.get("entrypoint")), as_list(svc.get("command")), *image)
        inv = Invocation(f"compose {name}", os.path.basename(entry[0]) if entry else "", entry[1:] + cmd)
        invs[name] = inv
        if inv.program in PROGRAMS:
            flags.check(inv)
        c.check(svc.get("restart") in ("always", "unless-stopped", "on-failure"), f"compose {name}: restart policy")
        build = svc.get("build", {})
        if build:
            c.check(os.path.isfile(os.path.join("docker", build.get("context", "."), build.get("dockerfile", "Dockerfile"))),
                    f"compose {name}: build names docker/Dockerfile in the repository root")
    coords = [n for n, i in invs.items() if i.program == "tessera-server"]
    workers = [n for n, i in invs.items() if i.program == "tessera-worker"]
    if not c.check(coords == ["coordinator"] and workers == ["worker"],
                   "compose: a coordinator (tessera-server) and a worker (tessera-worker) service",
                   f"servers {coords}, workers {workers}"):
        return
    coord, worker = services["coordinator"], services["worker"]
    port = listen_port(invs["coordinator"].args)
    url = urlparse(flag_value(invs["worker"].args, "--server") or "")
    c.check(url.scheme == "http" and url.hostname == "coordinator" and url.port == port,
            "compose: worker --server is http://coordinator:<its --listen port>", url.geturl())
    c.check(any(str(p).split(":")[-1] == str(port) for p in coord.get("ports", [])),
            "compose: coordinator publishes its --listen port", str(coord.get("ports")))
    data_dir = flag_value(invs["coordinator"].args, "--data-dir")
    c.check(any(str(v).split(":")[1:2] == [data_dir] for v in coord.get("volumes", [])),
            "compose: coordinator's --data-dir is a volume", f"{data_dir} vs {coord.get('volumes')}")
    test = " ".join(as_list(coord.get("healthcheck", {}).get("test")) or [])
    c.check(f":{port}/healthz" in test, "compose: coordinator healthcheck on /healthz of its port", test)
    env_c, env_w = coord.get("environment", {}), worker.get("environment", {})
    c.check({"TESSERA_CLIENT_TOKEN", "TESSERA_WORKER_TOKEN"} <= set(env_c), "compose: coordinator gets both tokens")
    c.check("TESSERA_WORKER_TOKEN" in env_w and "TESSERA_CLIENT_TOKEN" not in env_w,
            "compose: worker gets the worker token only")
    deps = worker.get("depends_on") or {}
    c.check("coordinator" in deps, "compose: worker depends on the coordinator")
    c.check(not (isinstance(deps, dict) and "service_healthy" in str(deps.get("coordinator"))),
            "compose: workers do not wait for the coordinator's health (podman-compose cannot; workers retry)")


def check_docs(c, root, flags):
    path = os.path.join(root, "docs", "deploy.md")
    if not c.check(os.path.isfile(path), "docs/deploy.md exists"):
        return
    text = open(path).read()
    n = 0
    for block in re.findall(r"```(?:sh|bash|console)?\n(.*?)```", text, re.S):
        for inv in shell_invocations(block, "docs/deploy.md", flags.subcommands):
            flags.check(inv)
            n += 1
    c.check(n >= 3, "docs/deploy.md: its commands run Tessera's programs", f"{n} invocations found")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--server", required=True)
    p.add_argument("--worker", required=True)
    p.add_argument("--cli", required=True)
    p.add_argument("--root", default=os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
    a = p.parse_args()
    bins = {"tessera-server": os.path.abspath(a.server), "tessera-worker": os.path.abspath(a.worker),
            "tessera": os.path.abspath(a.cli)}
    os.chdir(a.root)
    c = Checker()
    flags = FlagChecker(c, bins)
    docs = load_yaml_files(c, a.root)
    image = check_dockerfile(c, a.root, flags) or (["tessera-server"], [])
    check_install_modes(c, a.root)
    check_runtime_libraries(c, a.root, bins)
    check_compose(c, docs, image, flags)
    check_kubernetes(c, docs, image, flags)
    check_docs(c, a.root, flags)
    c.check(flags.checked >= 6, "flags checked against --help in Dockerfile, compose, k8s and docs",
            f"{flags.checked} invocations")
    print(f"{c.passed} passed, {c.failed} failed")
    return 1 if c.failed else 0


if __name__ == "__main__":
    sys.exit(main())
