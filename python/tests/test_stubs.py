"""The type stubs (alpenglow/_alpenglow.pyi) describe the native module:
every class, method, property and function they declare exists, and every
public name of the module is declared."""

import ast
import pathlib

import alpenglow
import alpenglow._alpenglow as native

STUBS = pathlib.Path(alpenglow.__file__).with_name("_alpenglow.pyi")
ALIASES = {"Vec3", "PathLike", "Frame", "FrameResult", "CameraArg"}


def declared():
    tree = ast.parse(STUBS.read_text())
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names.add(node.name)
            members[node.name] = {
                item.name for item in node.body if isinstance(item, ast.FunctionDef) and item.name != "__init__"
            }
        elif isinstance(node, ast.FunctionDef):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets)
    return names - ALIASES, members


def test_every_stub_exists_at_run_time():
    names, members = declared()
    for name in names:
        assert hasattr(native, name), name
    for cls, methods in members.items():
        for method in methods:
            assert hasattr(getattr(native, cls), method), f"{cls}.{method}"


def test_every_public_name_has_a_stub():
    names, _ = declared()
    public = {n for n in dir(native) if not n.startswith("_")}
    assert public <= names, public - names
    assert set(alpenglow.__all__) == public
