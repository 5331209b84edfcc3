#!/usr/bin/env python3
"""Import circles and layer breaches among the crate's modules, read from the source text (no compiler).

Every file under src/ is a module (`src/a/b.rs` and `src/a/b/mod.rs` are `a::b`). A module depends on another
when it names it in a path: `crate::x::y`, `super::y`, `self::y` (in `use` lines and in code), resolved to the
deepest module that exists. Edges between a module and its own ancestors are left out: a parent declares and
re-exports its children and the children use the parent's types, which is how Rust modules are built, not a
circle. What remains must be acyclic: the script prints every strongly connected component of two or more
modules (Tarjan) and every import from a top-level module to one above it in the layer order of src/lib.rs,
and exits 1 if it found any.

    python3 scripts/module_cycles.py            # from the repository root
"""

import re
import sys
from pathlib import Path

# The layers of src/lib.rs, lowest first: a module may import from its own layer and the ones before it.
LAYERS = ["math", "geometry", "material", "model", "solver", "post", "study", "io", "design", "run", "bench", "sweep", "cli"]

PATH = re.compile(r"\b(crate|super|self)((?:::[A-Za-z_][A-Za-z0-9_]*)+)")
TEST_MODULE = re.compile(r"#\[cfg\(test\)\]\s*mod\s+([a-z_]+)\s*\{")
GROUP = re.compile(r"\b(crate|super|self)((?:::[A-Za-z_][A-Za-z0-9_]*)*)::\{([^}]*)\}", re.S)


def module_of(path: Path, src: Path) -> tuple:
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


def strip_comments(text: str) -> str:
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return "\n".join(line.split("//")[0] for line in text.splitlines())


def resolve(base: tuple, names: list, modules: set) -> tuple:
    """The deepest existing module along `base + names`."""
    found = base
    current = base
    for name in names:
        current = current + (name,)
        if current in modules:
            found = current
        else:
            break
    return found


def main() -> int:
    src = Path(__file__).resolve().parent.parent / "src"
    # Each file's text, with an inline test module (`#[cfg(test)] mod tests { … }`, at the end of a file by
    # the crate's style) split off as a module of its own, a child of the file's module.
    texts = {}
    for path in src.rglob("*.rs"):
        module = module_of(path, src)
        text = strip_comments(path.read_text())
        test = TEST_MODULE.search(text)
        if test:
            texts[module + (test.group(1),)] = (text[test.end():], module)
            text = text[: test.start()]
        texts[module] = (text, module)
    modules = set(texts)
    edges = {m: set() for m in modules}
    for module, (text, scope) in texts.items():
        # `self` and `super` are relative to the file's module (an inline module's `super` is the file's).
        if scope != module:
            text = text.replace("super::", "self::")
        module_for_paths = scope
        paths = []
        for m in GROUP.finditer(text):
            head, prefix, inner = m.group(1), m.group(2), m.group(3)
            for item in inner.split(","):
                item = item.strip().split(" as ")[0].strip()
                if item and item != "self":
                    paths.append((head, prefix + "::" + item.split("::{")[0]))
        for m in PATH.finditer(text):
            paths.append((m.group(1), m.group(2)))
        for head, rest in paths:
            names = [n for n in rest.split("::") if n]
            if head == "crate":
                base = ()
            elif head == "self":
                base = module_for_paths
            else:  # super
                base = module_for_paths[:-1]
                while names and names[0] == "super":
                    names = names[1:]
                    base = base[:-1]
            target = resolve(base, names, modules)
            if target == module or not target:
                continue
            # Ancestor/descendant edges are the module tree itself.
            if target == module[: len(target)] or module == target[: len(module)]:
                continue
            edges[module].add(target)

    problems = 0
    # Tarjan's strongly connected components.
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]

    def connect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            comps.append(comp)

    sys.setrecursionlimit(10000)
    for v in sorted(modules):
        if v not in index:
            connect(v)
    for comp in comps:
        if len(comp) > 1:
            problems += 1
            names = sorted("::".join(c) for c in comp)
            print("import circle: " + ", ".join(names))
            for a in sorted(comp):
                for b in sorted(edges[a] & set(comp)):
                    print(f"    {'::'.join(a)} -> {'::'.join(b)}")
    for module in sorted(modules):
        if not module or module[0] not in LAYERS:
            continue
        for target in sorted(edges[module]):
            if target and target[0] in LAYERS and LAYERS.index(target[0]) > LAYERS.index(module[0]):
                problems += 1
                print(f"layer breach: {'::'.join(module)} imports {'::'.join(target)}")
    edge_count = sum(len(e) for e in edges.values())
    print(f"{len(modules)} modules, {edge_count} imports between them (module tree edges left out): "
          f"{problems} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
