"""The layering check of the Rust crates, as import-linter's layers contract is for the package.

Reads the declared order of each crate from ``crates/layers.toml`` and the crate's sources,
and fails (exit 1) on

- a reference from a module to one of a higher layer, or between two independent modules
  of one layer (``a | b``), or from an independent module to one it may not use;
- a cycle between two files (a strongly connected component of the file graph);
- a cycle between two top-level modules (a folder or file of ``src``: ``dynamics``,
  ``kinematics``...) through any of their files, e.g. ``a.rs -> b/x.rs`` and ``b/y.rs -> a.rs``.
  The declared order already forbids one (it needs a reference upward or between independent
  modules), but an allowed reference could close one: a module cycle is never allowed;
- an allow-list entry that no longer matches anything (so the list can only shrink);

except the violations the allow-list names, each with its reason and the phase that removes it.

The graph is read from the text, not compiled (why hand-written: cargo-modules needs
rust-analyzer and checks cycles only, arch_test_core is unmaintained since 2021, archaven
has no file cycles nor a declared order; this is a few hundred lines with the allow-list we
need). An edge goes from a file to the file that defines what a path names:

- ``crate::a::b::Item``, ``super::Item``, ``self::child::Item``, and in a module's own file
  ``child::Item`` for a child module; ``use`` groups ``{a, b::{c, d}}`` are expanded;
- through the re-exports (``pub use``, ``pub(crate) use``) of the module it lands in, so that
  ``crate::Workspace`` is ``workspace.rs`` and not ``lib.rs``;
- and from the file of a type to a file with an inherent ``impl`` of it elsewhere: the
  type then has methods written there (``impl Mechanism { fn new }`` in the loader would
  hide an arrow from the model up to the loader; the house rule: a function of the upper
  module taking the object);
- references to an ancestor module's own file are left out (a child uses its parent's
  types; the parent declares its children), as are comments and a unit-test module
  ``#[cfg(test)] mod tests`` at the end of a file, of any visibility (``pub(crate) mod tests``
  shares fixtures with other modules' tests; tests may reach anything).

Usage: ``python tools/rust_layers.py [CONFIG]`` (default ``crates/layers.toml``); prints each
finding and a summary line per crate.
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
Module = tuple[str, ...]

_COMMENT = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_TESTS = re.compile(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+tests\s*\{.*", re.S)
_USE = re.compile(r"^[ \t]*(pub(?:\([^)]*\))?\s+)?use\s+([^;]*);", re.S | re.M)
_PATH = re.compile(r"(?<![\w:$])((?:crate|super|self)(?:\s*::\s*\w+)+)")
_IMPL = re.compile(r"^[ \t]*impl\b\s*(?:<[^{>]*>)?\s*([\w:]+)[^{;]*\{", re.M)
_REEXPORT_DEPTH = 16


def module_of(rel: Path) -> Module:
    """``a/b/mod.rs`` -> ``(a, b)``; ``a/b.rs`` -> ``(a, b)``; ``lib.rs`` -> ``()``."""
    parts = rel.with_suffix("").parts
    return parts[:-1] if parts[-1] in ("mod", "lib", "main") else parts


def strip(text: str) -> str:
    """The text without comments and without the unit tests at the end."""
    return _TESTS.sub("", _COMMENT.sub("", text))


def use_paths(tree: str) -> list[tuple[list[str], str]]:
    """The full paths of a use tree with the name each binds:
    ``a::{b, c::{self, e as f}}`` -> ([a, b], b), ([a, c], c), ([a, c, e], f)."""
    tree = " ".join(tree.split())
    if "{" not in tree:
        path, _, alias = tree.partition(" as ")
        segments = [s.strip() for s in path.split("::") if s.strip()]
        segments = [s for s in segments if s != "*"]
        return [(segments, alias.strip() or (segments[-1] if segments else ""))]
    head, rest = tree.split("{", 1)
    body = rest[: rest.rfind("}")]
    items, depth, start = [], 0, 0
    for i, ch in enumerate(body):
        depth += ch == "{"
        depth -= ch == "}"
        if ch == "," and depth == 0:
            items.append(body[start:i])
            start = i + 1
    items.append(body[start:])
    prefix = [s.strip() for s in head.split("::") if s.strip()]
    out = []
    for item in filter(str.strip, items):
        for sub, alias in use_paths(item):
            if sub == ["self"]:
                out.append((prefix, alias if alias != "self" else prefix[-1]))
            else:
                out.append((prefix + sub, alias))
    return out


@dataclass
class Crate:
    """A crate's files, modules, re-exports and file graph."""

    src: Path
    files: dict[Module, Path] = field(default_factory=dict)
    texts: dict[Module, str] = field(default_factory=dict)
    # module -> name -> the absolute path it re-exports
    reexports: dict[Module, dict[str, list[str]]] = field(default_factory=dict)
    # (the type's module, the module with an inherent impl of it) -> the type's name
    impls: dict[tuple[Module, Module], str] = field(default_factory=dict)

    @classmethod
    def read(cls, src: Path) -> Crate:
        crate = cls(src)
        for f in sorted(src.rglob("*.rs")):
            mod = module_of(f.relative_to(src))
            crate.files[mod] = f
            crate.texts[mod] = strip(f.read_text(encoding="utf-8"))
        for mod, text in crate.texts.items():
            names: dict[str, list[str]] = {}
            for m in _USE.finditer(text):
                if m.group(1) is None:
                    continue
                for path, alias in use_paths(m.group(2)):
                    absolute = crate.absolute(mod, path)
                    if absolute:
                        names[alias] = absolute
            crate.reexports[mod] = names
        return crate

    def rel(self, mod: Module) -> str:
        return self.files[mod].relative_to(self.src).as_posix()

    def absolute(self, mod: Module, path: list[str]) -> list[str] | None:
        """A path written in `mod` made absolute, or None when it leaves the crate."""
        if not path:
            return None
        head, rest = path[0], path[1:]
        if head == "crate":
            return rest
        if head == "self":
            return list(mod) + rest
        if head == "super":
            base = list(mod)
            while path and path[0] == "super":
                if not base:
                    return None
                base.pop()
                path = path[1:]
            return base + path
        if (*mod, head) in self.files:  # a child module, named from its parent's file
            return list(mod) + path
        return None

    def resolve(self, path: list[str], depth: int = 0) -> Module | None:
        """The module whose file defines what an absolute path names."""
        k = len(path)
        while k > 0 and tuple(path[:k]) not in self.files:
            k -= 1
        mod, rest = tuple(path[:k]), path[k:]
        if mod not in self.files:
            return None
        if rest and depth < _REEXPORT_DEPTH:
            target = self.reexports.get(mod, {}).get(rest[0])
            if target is not None:
                return self.resolve(target + rest[1:], depth + 1) or mod
        return mod

    def edges(self) -> dict[Module, set[Module]]:
        """File graph: module -> the modules whose files it references (ancestors left out)."""
        graph: dict[Module, set[Module]] = {mod: set() for mod in self.files}
        for mod, text in self.texts.items():
            paths = [p for m in _USE.finditer(text) for p, _ in use_paths(m.group(2))]
            code = _USE.sub("", text)
            paths += [re.sub(r"\s+", "", m.group(1)).split("::") for m in _PATH.finditer(code)]
            children = {c[-1] for c in self.files if c[:-1] == mod and c != mod}
            if children:
                child = re.compile(r"(?<![\w:$])(" + "|".join(sorted(children)) + r")((?:::\w+)+)")
                paths += [[m.group(1), *m.group(2).split("::")[1:]] for m in child.finditer(code)]
            for path in paths:
                absolute = self.absolute(mod, path)
                target = None if absolute is None else self.resolve(absolute)
                if target is not None and target != mod[: len(target)]:
                    graph[mod].add(target)
        for (owner, mod), _ in self.foreign_impls().items():
            graph[owner].add(mod)
        return graph

    def foreign_impls(self) -> dict[tuple[Module, Module], str]:
        """Inherent impls of a type defined in another file (not an ancestor): the type's
        file then offers methods written in the impl's file, an edge from the former to the
        latter (``impl Mechanism { fn new }`` in the loader puts the loader under the model)."""
        if self.impls:
            return self.impls
        for mod, text in self.texts.items():
            names = {a: p for m in _USE.finditer(text) for p, a in use_paths(m.group(2))}
            for m in _IMPL.finditer(text):
                header = text[m.start() : m.end()]
                *path, name = m.group(1).split("::")
                if re.search(r"\bfor\b", header) or re.search(rf"\b(?:struct|enum|union|type)\s+{name}\b", text):
                    continue
                written = path + [name] if path else names.get(name)
                absolute = None if written is None else self.absolute(mod, written)
                owner = None if absolute is None else self.resolve(absolute)
                if owner is not None and owner != mod and mod != owner[: len(mod)]:
                    self.impls[(owner, mod)] = name
        return self.impls


def cycles(graph: dict[Module, set[Module]]) -> list[list[Module]]:
    """The strongly connected components of more than one node (Tarjan's, iterative)."""
    index: dict[Module, int] = {}
    low: dict[Module, int] = {}
    stack: list[Module] = []
    on: set[Module] = set()
    out: list[list[Module]] = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


@dataclass
class Layers:
    """A declared order: layer index and independent siblings of each top-level module."""

    rank: dict[str, int]
    group: dict[str, int]
    independent: dict[str, set[str]]

    @classmethod
    def parse(cls, layers: list[str], may_use: dict[str, list[str]]) -> Layers:
        rank, group = {}, {}
        for i, entry in enumerate(layers):
            for name in (s.strip() for s in entry.split("|")):
                rank[name] = i
                group[name] = len(group)
        return cls(rank, group, {k: set(v) for k, v in may_use.items()})

    def violation(self, a: str, b: str) -> str | None:
        """Why a reference from top-level module a to b breaks the order, or None."""
        if a == b:
            return None
        if a in self.independent and b not in self.independent[a]:
            may = ", ".join(sorted(self.independent[a]))
            return f"{a} may use only {may}" if may else f"{a} may use no other module"
        ra, rb = self.rank[a], self.rank[b]
        if rb > ra:
            return f"upward: {a} (layer {ra}) -> {b} (layer {rb})"
        if rb == ra:
            return f"between independent modules of layer {ra}: {a} -> {b}"
        return None


def top(mod: Module) -> str:
    return mod[0] if mod else "lib"


def reason(entry: dict) -> str:
    return f"  [allowed: {entry['why']}; until {entry['until']}]"


def module_graph(graph: dict[Module, set[Module]]) -> dict[Module, set[Module]]:
    """The graph of the top-level modules: an edge wherever one of a module's files references
    a file of another (lib.rs, the crate's facade of re-exports, left out)."""
    modules: dict[Module, set[Module]] = {(top(m),): set() for m in graph if m}
    for mod, targets in graph.items():
        for target in targets:
            if mod and target and top(mod) != top(target):
                modules[(top(mod),)].add((top(target),))
    return modules


def module_cycle_findings(name: str, graph: dict[Module, set[Module]]) -> list[str]:
    """The cycles between top-level modules, each a finding (no allow-list entry excuses one)."""
    return [
        f"{name}: module cycle ({len(comp)}): {', '.join(m[0] for m in comp)}" for comp in cycles(module_graph(graph))
    ]


def layer_findings(name: str, crate: Crate, graph: dict, layers: Layers, allow: list[dict]) -> tuple[list, list, list]:
    """(violations, allowed lines, allow entries used) of the references between layers."""
    by_edge = {(a["from"], a["to"]): a for a in allow}
    found, allowed, used = [], [], []
    for mod in sorted(graph):
        for target in sorted(graph[mod]):
            a, b = top(mod), top(target)
            why = None if "lib" in (a, b) else layers.violation(a, b)
            if why is None:
                continue
            if (mod, target) in crate.impls:
                why += f" (its `{crate.impls[mod, target]}` gets methods there: make them functions of `{b}`)"
            line = f"{name}: {crate.rel(mod)} -> {crate.rel(target)}: {why}"
            entry = by_edge.get((crate.rel(mod), crate.rel(target)))
            if entry is None:
                found.append(line)
            else:
                used.append(entry)
                allowed.append(line + reason(entry))
    return found, allowed, used


def cycle_findings(name: str, crate: Crate, graph: dict, allow: list[dict]) -> tuple[list, list, list]:
    """(violations, allowed lines, allow entries used) of the file cycles: a cycle is allowed
    when an entry lists all its files; an entry listing a file in no cycle is a finding."""
    found, allowed, used = [], [], []
    in_cycles: set[str] = set()
    for comp in cycles(graph):
        files = sorted(crate.rel(m) for m in comp)
        in_cycles.update(files)
        line = f"{name}: file cycle ({len(files)}): {', '.join(files)}"
        entry = next((a for a in allow if set(files) <= set(a["cycle"])), None)
        if entry is None:
            found.append(line)
        else:
            used.append(entry)
            allowed.append(line + reason(entry))
    for entry in {id(e): e for e in used}.values():
        for gone in sorted(set(entry["cycle"]) - in_cycles):
            found.append(f"{name}: {gone} is in no cycle now: remove it from its allow-list entry")
    return found, allowed, used


def check(name: str, cfg: dict, root: Path = ROOT) -> tuple[list[str], list[str], int]:
    """(violations, allowed lines, number of file and module cycles) of one crate against its
    declared order and allow-list."""
    crate = Crate.read(root / cfg["src"])
    layers = Layers.parse(cfg["layers"], cfg.get("may_use", {}))
    graph = crate.edges()
    allow = cfg.get("allow", [])
    tops = {top(m) for m in crate.files} - {"lib"}
    found = [f"{name}: module `{m}` is in no layer of the declared order" for m in sorted(tops - set(layers.rank))]
    found += [f"{name}: layer `{m}` has no source file: remove it" for m in sorted(set(layers.rank) - tops)]
    if found:
        return found, [], 0
    edges = layer_findings(name, crate, graph, layers, [a for a in allow if "to" in a])
    loops = cycle_findings(name, crate, graph, [a for a in allow if "cycle" in a])
    used = {id(a) for a in edges[2] + loops[2]}
    for entry in allow:
        if id(entry) not in used:
            what = ", ".join(entry["cycle"]) if "cycle" in entry else f"{entry['from']} -> {entry['to']}"
            found.append(f"{name}: allow-list entry matches nothing now, remove it: {what}")
    modules = module_cycle_findings(name, graph)
    n_cycles = sum(line.startswith(f"{name}: file cycle") for line in edges[1] + loops[0] + loops[1])
    return edges[0] + loops[0] + modules + found, edges[1] + loops[1], n_cycles + len(modules)


def main(argv: list[str]) -> int:
    config = Path(argv[1]) if len(argv) > 1 else ROOT / "crates" / "layers.toml"
    crates = tomllib.loads(config.read_text(encoding="utf-8"))
    failed = False
    for name, cfg in crates.items():
        found, allowed, n_cycles = check(name, cfg, config.resolve().parents[1])
        print("\n".join(allowed + found) or f"{name}: no violation")
        print(f"{name}: {n_cycles} file or module cycle(s), {len(allowed)} allowed, {len(found)} violation(s)")
        failed |= bool(found)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
