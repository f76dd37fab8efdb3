"""python/sonarbench/_core.pyi: the stubs name exactly what the module has."""

import ast
import pathlib

import sonarbench as sb
import sonarbench._core as core


def stub_tree():
    return ast.parse((pathlib.Path(sb.__file__).parent / "_core.pyi").read_text())


def public(names):
    return {n for n in names if not n.startswith("_") or n == "__version__"}


def test_every_public_name_has_a_stub_and_back():
    tree = stub_tree()
    stubbed = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            stubbed.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            stubbed.add(node.target.id)
    assert public(stubbed) - {"_Path"} == public(dir(core))
    assert set(sb.__all__) == public(dir(core))


def test_every_class_member_has_a_stub_and_back():
    for node in stub_tree().body:
        if not isinstance(node, ast.ClassDef) or node.name in ("InputError", "MachineError"):
            continue
        stubbed = {f.name for f in node.body if isinstance(f, ast.FunctionDef)}
        actual = {n for n in vars(getattr(core, node.name)) if not n.startswith("_")}
        assert public(stubbed) == actual, node.name
