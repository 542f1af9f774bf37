"""The repository's import graph: the package imports neither the benchmarks nor the tests, no peer
model imports the work-precision sweep or the bench, and no module of ``python/armdyn``,
``benchmarks`` or ``tests`` takes part in an import cycle (module- and function-level imports
alike). Read from the sources with ``ast``; nothing is imported."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _modules() -> dict[str, Path]:
    """Module name -> file, as each is imported: ``armdyn.*`` (from python/), ``benchmarks.*``
    (from the root), and the tests' own modules (tests/ is on sys.path)."""
    mods = {}
    for base, folder in ((ROOT / "python", "armdyn"), (ROOT, "benchmarks"), (ROOT / "tests", "")):
        for p in (base / folder).rglob("*.py"):
            parts = list(p.relative_to(base).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            mods[".".join(parts)] = p
    return mods


def _graph() -> dict[str, set[str]]:
    mods = _modules()

    def resolve(name: str) -> str | None:
        name = name.removeprefix("tests.")  # benchmarks may import the oracles as tests.oracles
        while name:
            if name in mods:
                return name
            name = name.rpartition(".")[0]
        return None

    graph = {}
    for name, path in mods.items():
        pkg = name if path.name == "__init__.py" else name.rpartition(".")[0]
        deps = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    head = pkg.split(".")[: len(pkg.split(".")) - node.level + 1]
                    base = ".".join([*head, base] if base else head)
                # `from package import name`: the submodule if there is one, else the package;
                # the compiled armdyn._core is a leaf
                targets = [f"{base}.{a.name}" for a in node.names if a.name != "_core"] or []
                if not targets and base:
                    continue
            else:
                continue
            for t in targets:
                r = resolve(t)
                if r is not None and r != name:
                    deps.add(r)
        graph[name] = deps
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = 0
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_no_import_cycles():
    graph = _graph()
    assert {"armdyn", "benchmarks.bench", "benchmarks.peers.geared", "oracles.numpy_rne"} <= set(
        graph
    )
    assert _cycles(graph) == []


def test_the_package_imports_neither_benchmarks_nor_tests():
    graph = _graph()
    for name, deps in graph.items():
        if name == "armdyn" or name.startswith("armdyn."):
            assert all(d == "armdyn" or d.startswith("armdyn.") for d in deps), (name, deps)


def test_no_peer_imports_the_sweep():
    graph = _graph()
    peers = [m for m in graph if m.startswith("benchmarks.peers")]
    assert len(peers) >= 5
    for m in peers:
        assert not graph[m] & {"benchmarks.workprecision", "benchmarks.bench"}, m
    assert graph["benchmarks.common"] == set()  # the shared helpers import nothing else here


def test_the_cycle_check_sees_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
