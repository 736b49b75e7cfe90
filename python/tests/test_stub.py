"""The type stub shipped beside the module (caliber/__init__.pyi) against the module itself: the
same public names, the same members of every class (properties as properties, static methods as
static methods), and for every function, method and constructor the same parameters in the same
order, of the same kind (positional or keyword-only), with the same defaults."""
import ast
import inspect
import os
import re

import pytest

import caliber

STUB = os.path.join(os.path.dirname(caliber.__file__), "caliber", "__init__.pyi")


def load_stub():
    with open(STUB, encoding="utf-8") as f:
        return ast.parse(f.read())


def public(name):
    return not name.startswith("_") or name in ("__init__", "__len__")


def literal(text):
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def split_top(text):
    """Splits at the commas outside brackets and quotes."""
    parts, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    if text[start:].strip():
        parts.append(text[start:].strip())
    return parts


def doc_params(obj, name):
    """The parameters of a pybind11 function, from the signature its docstring starts a line with:
    [(name, keyword_only, default)], self left out."""
    for line in (obj.__doc__ or "").splitlines():
        m = re.match(r"^(?:\d+\. )?" + re.escape(name) + r"\((.*)\) -> ", line.strip())
        if not m:
            continue
        out, keyword_only = [], False
        for part in split_top(m.group(1)):
            if part == "*":
                keyword_only = True
                continue
            pname, _, rest = part.partition(":")
            default = rest.partition("=")[2].strip() if "=" in rest else None
            if pname.strip() != "self":
                out.append((pname.strip(), keyword_only, None if default is None else literal(default)))
        return out
    return None


def runtime_params(obj, name):
    params = doc_params(obj, name)
    if params is not None:
        return params
    sig = inspect.signature(obj)  # Python functions, and caliber.query's text signature
    return [(p.name, p.kind == p.KEYWORD_ONLY, None if p.default is p.empty else p.default)
            for p in sig.parameters.values() if p.name != "self"]


def stub_params(node):
    args = node.args
    positional = args.posonlyargs + args.args
    defaults = [None] * (len(positional) - len(args.defaults)) + [ast.literal_eval(d) for d in args.defaults]
    out = [(a.arg, False, d) for a, d in zip(positional, defaults) if a.arg != "self"]
    kw_defaults = [None if d is None else ast.literal_eval(d) for d in args.kw_defaults]
    return out + [(a.arg, True, d) for a, d in zip(args.kwonlyargs, kw_defaults)]


def decorators(node):
    return {d.id for d in node.decorator_list if isinstance(d, ast.Name)}


def stub_members(cls_node):
    return {n.name: n for n in cls_node.body if isinstance(n, ast.FunctionDef) and public(n.name)}


STUB_TREE = load_stub()
STUB_CLASSES = {n.name: n for n in STUB_TREE.body if isinstance(n, ast.ClassDef)}
STUB_FUNCTIONS = {n.name: n for n in STUB_TREE.body if isinstance(n, ast.FunctionDef)}


def test_the_stub_is_shipped_beside_the_module():
    assert os.path.isfile(STUB)
    assert any(isinstance(n, ast.AnnAssign) and n.target.id == "__version__" for n in STUB_TREE.body)


def test_the_stub_names_what_the_module_holds():
    names = {n for n in dir(caliber) if public(n) and n != "distributed"}
    assert names == set(STUB_CLASSES) | set(STUB_FUNCTIONS)


@pytest.mark.parametrize("name", sorted(n for n in dir(caliber) if inspect.isclass(getattr(caliber, n))))
def test_every_class_has_the_stub_members(name):
    cls, node = getattr(caliber, name), STUB_CLASSES[name]
    members = stub_members(node)
    if name == "Error":
        assert members == {}
        return
    runtime = {k: v for k, v in vars(cls).items() if public(k)}
    if "__init__" not in members:  # the classes the module makes, never the user
        runtime.pop("__init__", None)
    assert set(runtime) == set(members), name
    for member, value in runtime.items():
        kinds = decorators(members[member])
        assert isinstance(value, property) == ("property" in kinds), (name, member)
        assert isinstance(value, staticmethod) == ("staticmethod" in kinds), (name, member)
        if isinstance(value, property) or member == "__len__":
            continue
        function = value.__func__ if isinstance(value, staticmethod) else value
        assert runtime_params(function, member) == stub_params(members[member]), (name, member)


@pytest.mark.parametrize("name", sorted(STUB_FUNCTIONS))
def test_every_function_has_the_stub_signature(name):
    assert runtime_params(getattr(caliber, name), name) == stub_params(STUB_FUNCTIONS[name])


def test_the_check_sees_a_wrong_stub():
    # A parameter renamed, a default changed or a keyword made positional must show as a difference.
    good = stub_params(STUB_FUNCTIONS["query"])
    wrong = ast.parse("def query(a, pose_a, b, pose_b, kind='interference', tolerance=None, angle=30.0, "
                      "max_pairs=1, *, lowest_ids=False): ...").body[0]
    assert runtime_params(caliber.query, "query") == good
    assert stub_params(wrong) != good
