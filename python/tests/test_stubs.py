"""The type stubs and the extension agree on defaults, and `help()` shows them (no `...`)."""

import ast
import inspect
from pathlib import Path

import kantele
import kantele._kantele as native

STUB = Path(kantele.__file__).with_name("_kantele.pyi")


def stub_functions():
    """(class name or None, function node) of every function in the stub."""
    tree = ast.parse(STUB.read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            yield None, node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    yield node.name, item


def stub_defaults(function: ast.FunctionDef):
    """Parameter name -> the stub's literal default."""
    args = function.args
    positional = args.posonlyargs + args.args
    pairs = list(zip(positional[len(positional) - len(args.defaults):], args.defaults))
    pairs += [(a, d) for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None]
    out = {}
    for arg, node in pairs:
        try:
            out[arg.arg] = ast.literal_eval(node)
        except ValueError:
            continue
    return out


def same(a, b) -> bool:
    if isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)):
        return list(a) == list(b)
    return a == b and type(a) is type(b) or (isinstance(a, float) and a == b)


def test_help_shows_the_stub_defaults():
    checked = 0
    for owner_name, function in stub_functions():
        owner = getattr(native, owner_name) if owner_name else native
        runtime = getattr(owner, function.name, None)
        if runtime is None or not callable(runtime):
            continue
        signature = inspect.signature(runtime)
        where = f"{owner_name + '.' if owner_name else ''}{function.name}"
        for name, expected in stub_defaults(function).items():
            parameter = signature.parameters.get(name)
            assert parameter is not None, f"{where}: the extension has no parameter {name}"
            assert parameter.default is not Ellipsis, f"{where}({name}=...): help() shows `...`"
            assert same(parameter.default, expected), (
                f"{where}({name}): extension {parameter.default!r}, stub {expected!r}"
            )
            checked += 1
    assert checked > 30, checked
