"""The package's layout holds: renderers side by side, kernels on shared helpers only, no
private names borrowed across packages, and every registry entry complete.

The rules are those of ``docs/extending.md``; each test reads the source (``ast``), so a new
module is checked the day it lands.
"""

import ast
from pathlib import Path

import pytest

import vrlib
from vrlib.parallel.composite import COMPOSITORS, Compositor

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "vrlib"

#: The rendering methods' modules, and the reference renderer beside them.
RENDERERS = sorted({fn.__module__ for fn in vrlib.METHODS.values()} | {"vrlib.reference"})
#: Kernel modules every kernel may use; the renderers' own kernels are not among them.
SHARED_KERNELS = {"vrlib._kernels._jit", "vrlib._kernels.filters", "vrlib._kernels.sampling",
                  "vrlib._kernels.camera", "vrlib._kernels.tables",
                  "vrlib._kernels.shading", "vrlib._kernels.footprint",
                  "vrlib._kernels.preintegration", "vrlib._kernels.queue",
                  "vrlib._kernels.packets"}


def module_name(path):
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path):
    """``(module, name)`` for every import in a file (``name`` None for ``import module``);
    names imported from a package that are its submodules count as modules."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, None) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                sub = ROOT.joinpath(*node.module.split("."), alias.name)
                if sub.with_suffix(".py").exists() or (sub / "__init__.py").exists():
                    found.append((f"{node.module}.{alias.name}", None))
                else:
                    found.append((node.module, alias.name))
    return found


def sources(*folders):
    return sorted(p for folder in folders for p in (ROOT / folder).rglob("*.py"))


def test_the_layout_is_what_the_rules_name():
    """The rules below test something: the renderers and shared kernels they name exist."""
    assert RENDERERS == ["vrlib.raycast", "vrlib.reference", "vrlib.shear", "vrlib.shearwarp",
                         "vrlib.splat"]
    for name in SHARED_KERNELS:
        assert (ROOT / (name.replace(".", "/") + ".py")).exists(), name


@pytest.mark.parametrize("renderer", RENDERERS)
def test_renderers_sit_side_by_side(renderer):
    """No renderer imports another renderer (what they share lives in neutral modules)."""
    path = ROOT / (renderer.replace(".", "/") + ".py")
    others = set(RENDERERS) - {renderer}
    borrowed = {module for module, _ in imports(path) if module in others}
    assert not borrowed, f"{renderer} imports {sorted(borrowed)}"


@pytest.mark.parametrize("path", sources("vrlib/_kernels"), ids=lambda p: p.stem)
def test_kernels_import_only_shared_kernel_helpers(path):
    """A kernel imports NumPy, numba, the standard library and the shared kernel helpers:
    never another renderer's kernel, nor the Python side of the package."""
    for module, _ in imports(path):
        if module.startswith("vrlib"):
            assert module in SHARED_KERNELS | {"vrlib._kernels"}, f"{path.name}: {module}"


@pytest.mark.parametrize("path", sources("vrlib", "data_gen", "chapters"),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_no_private_names_across_modules(path):
    """No module imports a private name (``_name``) of another module, and nothing outside
    vrlib imports its private modules (``vrlib._kernels``, ``vrlib._scheduling``...); inside a
    package, its private helper modules are its own."""
    this = module_name(path)
    package = this.split(".")[0]
    for module, name in imports(path):
        if name is not None and name.startswith("_") and not name.startswith("__"):
            pytest.fail(f"{this} imports the private name {name} from {module}")
        parts = module.split(".")
        if parts[0] in ("vrlib", "data_gen", "chapters") and parts[0] != package:
            private = [p for p in parts[1:] if p.startswith("_") and p != "__main__"]
            assert not private, f"{this} imports the private module {module}"


@pytest.mark.parametrize("path", sources("vrlib", "data_gen", "chapters"),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_no_private_attributes_of_other_modules(path):
    """No module reads a private attribute of a module it imported (``raycast._lookup``) or
    a volume's private cache (``volume._derived``: :meth:`vrlib.Volume.cached` is the way)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    aliases = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import | ast.ImportFrom):
            aliases |= {(alias.asname or alias.name).split(".")[0] for alias in node.names}
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and \
                not node.attr.startswith("__"):
            if isinstance(node.value, ast.Name) and node.value.id in aliases:
                pytest.fail(f"{path.name}:{node.lineno} reads {node.value.id}.{node.attr}")
            if node.attr == "_derived" and path.name != "volume.py":
                pytest.fail(f"{path.name}:{node.lineno} touches a volume's private cache")


def test_every_method_has_a_naive_twin():
    """The cost chapter times each method's naive twin (``tests/naive.py``): a method added to
    :data:`vrlib.METHODS` needs one."""
    import naive

    assert set(naive.TWINS) == set(vrlib.METHODS)


@pytest.mark.parametrize("name", list(COMPOSITORS))
def test_every_compositor_has_both_faces(name):
    """A compositor implements both the MPI algorithm and its simulated frame, under its
    registry name."""
    compositor = COMPOSITORS[name]
    assert isinstance(compositor, Compositor) and compositor.name == name
    for face in ("composite", "rounds"):
        assert getattr(type(compositor), face) is not getattr(Compositor, face), face


def test_the_rules_catch_what_they_forbid(tmp_path):
    """The import reader sees a renderer importing another and a private name borrowed."""
    bad = tmp_path / "bad.py"
    bad.write_text("from vrlib.raycast import cast_rays\nfrom vrlib.volume import _hidden\n"
                   "import vrlib._kernels.raycast\nfrom vrlib import shear\n")
    found = imports(bad)
    assert ("vrlib.raycast", "cast_rays") in found
    assert ("vrlib.volume", "_hidden") in found
    assert ("vrlib._kernels.raycast", None) in found
    assert ("vrlib.shear", None) in found


def test_the_sources_pass_the_linter():
    """``ruff check`` (the rules in pyproject.toml) finds nothing: an undefined name in dead
    code after a return (F821) once landed unnoticed, since no test ran that code."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "ruff", "check", "--quiet", str(ROOT)],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr
