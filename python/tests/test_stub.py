"""The type stub shipped beside the module (caliber/__init__.pyi) against the module itself: the
same public names, the same members of every class (properties as properties, static methods as
static methods), and for every function, method and constructor the same parameters in the same
order, of the same kind (positional or keyword-only), with the same defaults."""
import ast
import inspect
import os
import re
import types

import pytest

import caliber

STUB = os.path.join(os.path.dirname(caliber.__file__), "caliber", "__init__.pyi")


def load_stub():
    with open(STUB, encoding="utf-8") as f:
        return ast.parse(f.read())


NO_DEFAULT = object()  # a parameter without a default (None is a default)


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
            default = literal(rest.partition("=")[2].strip()) if "=" in rest else NO_DEFAULT
            if pname.strip() != "self":
                out.append((pname.strip(), keyword_only, default))
        return out
    return None


def runtime_params(obj, name):
    params = doc_params(obj, name)
    if params is not None:
        return params
    sig = inspect.signature(obj)  # Python functions, and caliber.query's text signature
    return [(p.name, p.kind == p.KEYWORD_ONLY, NO_DEFAULT if p.default is p.empty else p.default)
            for p in sig.parameters.values() if p.name != "self"]


def stub_params(node):
    args = node.args
    positional = args.posonlyargs + args.args
    defaults = [NO_DEFAULT] * (len(positional) - len(args.defaults)) + [ast.literal_eval(d) for d in args.defaults]
    out = [(a.arg, False, d) for a, d in zip(positional, defaults) if a.arg != "self"]
    kw_defaults = [NO_DEFAULT if d is None else ast.literal_eval(d) for d in args.kw_defaults]
    return out + [(a.arg, True, d) for a, d in zip(args.kwonlyargs, kw_defaults)]


def same(runtime, stub):
    """Parameters equal in name, kind and default, a default's type included (0 is not False)."""
    def key(params):
        return [(n, k, type(d).__name__, d) for n, k, d in params]
    return key(runtime) == key(stub)


def constructible(cls):
    """Whether the module lets a user build the class (pybind11 leaves the slot wrapper of
    object.__init__ on a class bound without a constructor)."""
    init = vars(cls).get("__init__")
    return init is not None and not isinstance(init, types.WrapperDescriptorType)


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
    assert ("__init__" in members) == constructible(cls), name
    if not constructible(cls):  # the classes the module makes, never the user
        runtime.pop("__init__", None)
    assert set(runtime) == set(members), name
    for member, value in runtime.items():
        kinds = decorators(members[member])
        assert isinstance(value, property) == ("property" in kinds), (name, member)
        assert isinstance(value, staticmethod) == ("staticmethod" in kinds), (name, member)
        if isinstance(value, property) or member == "__len__":
            continue
        function = value.__func__ if isinstance(value, staticmethod) else value
        assert same(runtime_params(function, member), stub_params(members[member])), (name, member)


@pytest.mark.parametrize("name", sorted(STUB_FUNCTIONS))
def test_every_function_has_the_stub_signature(name):
    assert same(runtime_params(getattr(caliber, name), name), stub_params(STUB_FUNCTIONS[name]))


@pytest.mark.parametrize("wrong", [
    "max_pairs=1, *, lowest_ids=False",     # a default changed
    "max_pairs=0, *, lowest_ids=0",         # a default of another type
    "max_pairs=0, lowest_ids=False",        # a keyword made positional
    "max_pairs=0, *, lowest_id=False",      # a parameter renamed
])
def test_the_check_sees_a_wrong_stub(wrong):
    good = stub_params(STUB_FUNCTIONS["query"])
    node = ast.parse("def query(a, pose_a, b, pose_b, kind='interference', tolerance=None, angle=30.0, " + wrong +
                     "): ...").body[0]
    assert same(runtime_params(caliber.query, "query"), good)
    assert not same(runtime_params(caliber.query, "query"), stub_params(node))


def test_a_required_parameter_is_not_a_none_default():
    node = ast.parse("def as_quaternion(self, order=None): ...").body[0]
    assert not same(runtime_params(caliber.Pose.as_quaternion, "as_quaternion"), stub_params(node))
