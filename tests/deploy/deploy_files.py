"""Readers for deploy_static_test.py: CLI11 --help text, Dockerfiles, .dockerignore, compose
interpolation and shell command lines. No checks here, only parsing."""
import re
import shlex
from dataclasses import dataclass, field

PROGRAMS = ("tessera-server", "tessera-worker", "tessera")


@dataclass
class Invocation:
    where: str
    program: str
    args: list


def flag_value(args, flag):
    """The value of --flag in args (`--flag V` or `--flag=V`), else None."""
    for i, a in enumerate(args):
        if a == flag and i + 1 < len(args):
            return args[i + 1]
        if a.startswith(flag + "="):
            return a[len(flag) + 1:]
    return None


def listen_port(args):
    v = flag_value(args, "--listen")
    return int(v.rsplit(":", 1)[1]) if v and ":" in v else 8420  # tessera-server's default


def effective(entry, cmd, image_entry, image_cmd):
    """Docker/Kubernetes semantics: a new entrypoint (command) drops the image's CMD."""
    if entry is not None:
        return list(entry), list(cmd or [])
    return list(image_entry), list(cmd if cmd is not None else image_cmd)


def as_list(v):
    if v is None:
        return None
    return shlex.split(v) if isinstance(v, str) else [str(x) for x in v]


@dataclass
class Option:
    takes_value: bool
    required: bool


@dataclass
class HelpSpec:
    options: dict = field(default_factory=dict)
    required: list = field(default_factory=list)
    subcommands: list = field(default_factory=list)


# CLI11 prints an option as `  -o,--output TEXT ...  description` or `  --wait  description`;
# a value's type is an upper-case word (TEXT, INT, UINT, FLOAT), maybe with `:CHECK` or `=DEFAULT`.
_OPTION = re.compile(r"^  ((?:-\w,)*--[\w-]+(?:,--[\w-]+)*)(?:\s+(.*))?$")
_TYPE = re.compile(r"^(TEXT|INT|UINT|FLOAT|DOUBLE|NUMBER|BOOLEAN|ENUM)\b")


def parse_help(text):
    spec = HelpSpec()
    in_subcommands = False
    for line in text.splitlines():
        if re.match(r"^\S.*:$", line):
            in_subcommands = line.startswith("Subcommands")
            continue
        if in_subcommands:
            m = re.match(r"^  ([a-z][\w-]*)\s", line)
            if m:
                spec.subcommands.append(m.group(1))
            continue
        m = _OPTION.match(line)
        if not m:
            continue
        rest = m.group(2) or ""
        opt = Option(takes_value=bool(_TYPE.match(rest)), required=" REQUIRED" in " " + rest.split("  ")[0])
        for name in m.group(1).split(","):
            if name.startswith("--"):
                spec.options[name] = opt
                if opt.required:
                    spec.required.append(name)
    return spec


@dataclass
class Instruction:
    op: str
    args: str


@dataclass
class Dockerfile:
    instructions: list

    def stages(self):
        out = []
        for i in self.instructions:
            if i.op == "FROM":
                out.append([])
            if out:
                out[-1].append(i)
        return out


def parse_dockerfile(text):
    """Instructions with continuation lines joined; comments and parser directives dropped."""
    instructions = []
    pending = ""
    for raw in text.splitlines():
        line = raw.strip()
        if not pending and (not line or line.startswith("#")):
            continue
        if pending and line.startswith("#"):
            continue  # a comment inside a continued instruction
        if line.endswith("\\"):
            pending += line[:-1] + " "
            continue
        full = (pending + line).strip()
        pending = ""
        if full:
            op, _, args = full.partition(" ")
            instructions.append(Instruction(op.upper(), args.strip()))
    return Dockerfile(instructions)


def dockerignore_rules(path):
    try:
        lines = open(path).read().splitlines()
    except OSError:
        return []
    rules = []
    for line in lines:
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        negate = line.startswith("!")
        pattern = line[1:] if negate else line
        rules.append((negate, _pattern_regex(pattern.strip("/"))))
    return rules


def _pattern_regex(pattern):
    # Docker's matcher (moby/patternmatcher): Go filepath.Match plus `**` for any number of folders.
    out = ""
    i = 0
    while i < len(pattern):
        ch = pattern[i]
        if pattern.startswith("**/", i):
            out += "(?:.*/)?"
            i += 3
            continue
        if pattern.startswith("**", i):
            out += ".*"
            i += 2
            continue
        out += {"*": "[^/]*", "?": "[^/]"}.get(ch, re.escape(ch))
        i += 1
    return re.compile(out + "$")


def ignored(rules, path):
    """Whether `path` (relative to the context) is left out: the last rule that matches it or one
    of its parent folders decides."""
    parts = path.strip("/").split("/")
    prefixes = ["/".join(parts[:k]) for k in range(1, len(parts) + 1)]
    result = False
    for negate, rx in rules:
        if any(rx.match(p) for p in prefixes):
            result = not negate
    return result


_VAR = re.compile(r"\$\{(\w+)(?::?([-?])([^}]*))?\}")


def interpolate(node):
    """Compose variable substitution with the defaults the file gives (`${X:-d}` -> d); a variable
    without a default (`${X}`, `${X:?msg}`) becomes <X>."""
    if isinstance(node, dict):
        return {k: interpolate(v) for k, v in node.items()}
    if isinstance(node, list):
        return [interpolate(v) for v in node]
    if isinstance(node, str):
        return _VAR.sub(lambda m: m.group(3) if m.group(2) == "-" else f"<{m.group(1)}>", node)
    return node


def pod_containers(doc):
    spec = doc.get("spec", {})
    tmpl = spec.get("template", spec.get("jobTemplate", {}).get("spec", {}).get("template", {}))
    return tmpl.get("spec", {}).get("containers", [])


_SHELL_STOP = {"|", "||", "&&", ";", "&", ">", ">>", "<", "2>", "2>&1", ")", "(", "$("}
_PREFIXES = {"exec", "sudo", "env", "time", "nohup", "--"}
_IMAGE = re.compile(r"^(?:[\w.-]+(?::\d+)?/)*tessera:[\w.-]+$")


def _command_position(words, i):
    if i == 0 or words[i - 1] in _SHELL_STOP or words[i - 1] in _PREFIXES:
        return True
    if re.match(r"^\w+=", words[i - 1]):  # VAR=value program ...
        return _command_position(words, i - 1)
    return i >= 2 and words[i - 2] == "exec"  # docker compose exec SERVICE program ...


def shell_invocations(script, where, subcommands):
    """Each run of tessera-server, tessera-worker or `tessera SUBCOMMAND` in shell text, with the
    words after it up to the end of the command: as a command (`./build/worker/tessera-worker`,
    `kubectl exec POD -- tessera jobs`, `docker compose exec SERVICE tessera jobs`), as
    `docker run --entrypoint PROGRAM IMAGE args` (the image right after it), or as
    `docker run ... tessera:TAG args` (the image's entrypoint, tessera-server)."""
    script = re.sub(r"\\\n", " ", script)
    found = []
    for line in script.splitlines():
        line = line.split(" #", 1)[0].strip()
        if not line or line.startswith("#"):
            continue
        try:
            lexer = shlex.shlex(line, posix=True, punctuation_chars="|&;<>()")
            lexer.whitespace_split = True
            words = list(lexer)
        except ValueError:
            continue
        docker_run = any(words[k] == "run" and words[k - 1] in ("docker", "podman") for k in range(1, len(words)))
        entrypoint = None
        for i, w in enumerate(words):
            name = w.rsplit("/", 1)[-1]
            first = None
            if name in PROGRAMS and i > 0 and words[i - 1] == "--entrypoint":
                entrypoint = name
                continue
            if name in PROGRAMS and _command_position(words, i):
                first, program = i + 1, name
            elif docker_run and _IMAGE.match(w) and words[i - 1] not in ("-t", "--tag"):
                first, program = i + 1, entrypoint or "tessera-server"
            if first is None:
                continue
            args = []
            for x in words[first:]:
                if x in _SHELL_STOP:
                    break
                args.append(x)
            if program == "tessera" and (not args or args[0] not in subcommands):
                continue  # a folder or image called tessera, not the program
            found.append(Invocation(f"{where}: `{line[:70]}`", program, args))
    return found
