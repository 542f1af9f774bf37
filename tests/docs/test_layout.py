"""The repository's import graph: the package imports neither the benchmarks nor the tests, no peer
model imports the work-precision sweep or the bench, and no module of ``python/armdyn``,
``benchmarks`` or ``tests`` takes part in an import cycle (module- and function-level imports
alike), and the library never imports the papers' reproduction (``armdyn.papers``) but through
the thin re-exports at the papers' old paths and the ``armdyn reproduce`` command. Read from the
sources with ``ast``; the last check also imports every library module in a subprocess."""

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


def test_the_viewer_asks_the_loader_for_the_urdf():
    """simulate/rollout do not import the viewer, and the URDF loader does not push its file to
    it: the viewer (armdyn.animation) imports the loader's armdyn.urdf.urdf_source."""
    graph = _graph()
    assert "armdyn.animation" not in graph["armdyn.simulation"]
    assert "armdyn.animation" not in graph["armdyn.urdf"]
    assert "armdyn.urdf" in graph["armdyn.animation"]


def test_the_cycle_check_sees_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


#: the library's modules that may import armdyn.papers: thin re-exports at the papers' old,
#: documented paths (each nothing but imports and a module ``__getattr__``/``__dir__``
#: forwarding to its new home; ``armdyn.scenes`` finds the papers' arms only on first use)
PAPERS_SHIMS = {
    "armdyn.reproduce": "armdyn.papers.reproduce",
    "armdyn.geared_study": "armdyn.papers.geared_study",
    "armdyn.scenes.paper": "armdyn.papers.five_dof",
    "armdyn.scenes.geared_arm": "armdyn.papers.geared_arm",
    "armdyn.scenes": "armdyn.papers.five_dof armdyn.papers.geared_arm",
}


#: the command line: ``armdyn reproduce`` runs the papers' reproduction, imported inside the
#: command's branch when it runs (never at module level)
CLI = {"armdyn.__main__": "armdyn.papers.reproduce"}


def _is_papers(name: str) -> bool:
    return name == "armdyn.papers" or name.startswith("armdyn.papers.")


def test_the_library_never_imports_the_papers():
    graph = _graph()
    library = [m for m in graph if m.startswith("armdyn") and not _is_papers(m)]
    assert {"armdyn", "armdyn.simulation", "armdyn.scenes", "armdyn.reproduce"} <= set(library)
    offenders = {
        m: sorted(d for d in graph[m] if _is_papers(d))
        for m in library
        if m not in PAPERS_SHIMS | CLI and any(_is_papers(d) for d in graph[m])
    }
    assert offenders == {}, f"library modules importing armdyn.papers: {offenders}"
    for cli, target in CLI.items():
        assert {d for d in graph[cli] if _is_papers(d)} == {target}, cli
        top = ast.parse(_modules()[cli].read_text(encoding="utf-8")).body
        assert not any(isinstance(n, ast.ImportFrom) and _is_papers(n.module or "") for n in top), (
            f"{cli} imports the papers at module level"
        )
    for shim, targets in PAPERS_SHIMS.items():
        assert {d for d in graph[shim] if _is_papers(d)} == set(targets.split()), shim


def test_the_papers_shims_are_thin():
    """Each old path holds imports and the forwarding functions only; its papers imports in
    ``armdyn.scenes`` sit inside ``__getattr__`` (so ``import armdyn`` does not run them)."""
    for shim in PAPERS_SHIMS:
        path = _modules()[shim]
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
                continue  # the docstring
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                assert not _is_papers(node.module or "") or shim != "armdyn.scenes", shim
                continue
            if isinstance(node, ast.Assign) and [t.id for t in node.targets] == ["__all__"]:
                continue
            assert isinstance(node, ast.FunctionDef) and node.name in ("__getattr__", "__dir__"), (
                shim,
                ast.dump(node)[:80],
            )


def test_importing_the_library_loads_no_papers_module():
    """Every library module imported (the shims aside): armdyn.papers is not among sys.modules."""
    import subprocess
    import sys

    library = sorted(
        m
        for m in _modules()
        if m.startswith("armdyn") and not _is_papers(m) and m not in PAPERS_SHIMS
    )
    code = (
        "import importlib, sys\n"
        f"for m in {library!r}: importlib.import_module(m)\n"
        "print(sorted(m for m in sys.modules if m.startswith('armdyn.papers')))\n"
        "import armdyn\n"
        "assert armdyn.scenes.geared_arm_6dof is importlib.import_module("
        "'armdyn.papers.geared_arm').geared_arm_6dof\n"
    )
    import armdyn

    # the armdyn this test imported (installed, as in CI, or a source tree on PYTHONPATH)
    env = {
        **__import__("os").environ,
        "PYTHONPATH": str(Path(armdyn.__file__).resolve().parents[1]),
    }
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    assert out.stdout.strip() == "[]", out.stdout
