"""Calls that do not fit a function's signature, said as Python says them and naming the function as
evlife.NAME (pybind11 said "read(): incompatible function arguments" with every argument printed, and
named neither the argument missing nor the keyword misspelt)."""
import ast
import contextlib
import functools
import inspect

from . import _evlife

_P = inspect.Parameter


def public(wrapper, qualname=None):
    """`wrapper` (functools.wraps of a C++ function) named evlife.NAME (or
    evlife.QUALNAME, a method's: LifetimeEstimator.process), where pickle
    finds it: wraps copied the C++ function's evlife._evlife and
    PyCapsule.NAME, which pickle cannot look up, so no function could be sent
    to a Dask worker or a multiprocessing.Pool."""
    wrapper.__module__ = "evlife"
    wrapper.__qualname__ = qualname or wrapper.__name__
    wrapped = getattr(wrapper, "__wrapped__", None)
    if wrapped is not None:  # a C++ function's: inspect.signature() and help() had none
        wrapper.__signature__ = _signature(wrapped)
    return wrapper


class _Default:
    """A default as pybind11 wrote it, where it is no Python literal: shown as written."""

    def __init__(self, text):
        self.text = text

    def __repr__(self):
        return self.text


def _signature(function):
    """A Python function's signature; a C++ function's from the line pybind11 writes first in its
    __doc__ ("read(path: os.PathLike, sensor: object = None, *, from_s: ... = None, **kwargs) ->
    numpy.ndarray"), with its annotations and defaults as written and a method's self positional
    only."""
    try:
        return inspect.signature(function)
    except ValueError:  # a C++ function
        pass
    line = function.__doc__.partition("\n")[0]
    head = line[line.index("("):]
    params, _, returns = head.rpartition(" -> ")
    a = ast.parse("def f%s: pass" % params).body[0].args

    def annotation(node):
        return _P.empty if node is None else ast.unparse(node)

    def default(node):
        try:
            return ast.literal_eval(node)
        except ValueError:
            return _Default(ast.unparse(node))
    positional = a.posonlyargs + a.args
    first_default = len(positional) - len(a.defaults)
    parameters = [_P(p.arg, _P.POSITIONAL_ONLY if i < len(a.posonlyargs) or (i, p.arg) == (0, "self")
                     else _P.POSITIONAL_OR_KEYWORD, annotation=_P.empty if p.arg == "self" else annotation(p.annotation),
                     default=_P.empty if i < first_default else default(a.defaults[i - first_default]))
                  for i, p in enumerate(positional)]
    parameters += [_P(a.vararg.arg, _P.VAR_POSITIONAL)] if a.vararg else []
    parameters += [_P(p.arg, _P.KEYWORD_ONLY, annotation=annotation(p.annotation),
                      default=_P.empty if d is None else default(d))
                   for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    parameters += [_P(a.kwarg.arg, _P.VAR_KEYWORD)] if a.kwarg else []
    return inspect.Signature(parameters, return_annotation=returns.strip() or _P.empty)


def naming_arguments(function, qualname=None):
    """`function` (of the C++ module, or of the package) as a public function (public) whose calls are
    checked as `checking` says."""
    checked = checking(function, qualname)

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with checked(args, kwargs):
            return function(*args, **kwargs)
    return public(wrapper, qualname)


def checking(function, qualname=None):
    """`with checked(args, kwargs): function(*args, **kwargs)`: a TypeError raised in it, when the call
    does not fit the signature of `function` (evlife.QUALNAME), is replaced by one saying so in
    Python's words, as "evlife.read() missing required argument 'path'" or "evlife.formats() takes 0
    positional arguments but 1 was given", a keyword it has not with its did-you-mean (as the C++
    functions refuse theirs). Looked at only then: correct calls pay nothing.
    A context, not a wrapper: no frame of its own, so the C++ functions' warnings, at a fixed
    stacklevel, stay at the caller's line."""
    signature = _signature(function)
    where = "evlife." + (qualname or function.__name__).replace(".__init__", "")  # a class is called by its name
    # ... and without self: its arguments are counted as the call wrote them (LifetimeEstimator((8, 8), 1):
    # "takes 1 positional argument but 2 were given", not Python's "__init__() takes 2 ... but 3").
    constructor = (qualname or "").endswith(".__init__")
    if constructor:
        signature = signature.replace(parameters=list(signature.parameters.values())[1:])

    @contextlib.contextmanager
    def checked(args, kwargs):
        try:
            yield
        except TypeError:
            try:
                _refuse_call(where, signature, args[1:] if constructor else args, kwargs)
            except TypeError as e:
                raise e from None
            raise
    return checked


def _refuse_call(where, signature, args, kwargs):
    """TypeError when (args, kwargs) does not fit `signature`, in Python's order: a keyword it has not
    (where **kwargs takes any, e.g. estimator options: one misspelling a missing argument), one given
    twice, too many positional arguments, a required argument missing."""
    parameters = signature.parameters.values()
    named = [p for p in parameters if p.kind not in (_P.VAR_POSITIONAL, _P.VAR_KEYWORD)]
    keywords = [p.name for p in named if p.kind != _P.POSITIONAL_ONLY]
    positional = [p for p in named if p.kind != _P.KEYWORD_ONLY]
    by_position = [p.name for p in positional[:len(args)]]
    given = by_position + list(kwargs)
    missing = [p.name for p in named if p.default is _P.empty and p.name not in given]
    any_keyword = any(p.kind == _P.VAR_KEYWORD for p in parameters)
    unknown = [k for k in kwargs if k not in keywords
               and (not any_keyword or _evlife._misspelled_keyword(k, missing, keywords))]
    if unknown:
        # A name the call already gives is not what it misspelled.
        _evlife._refuse_keywords(where, {unknown[0]: kwargs[unknown[0]]}, [k for k in keywords if k not in given])
    twice = [k for k in kwargs if k in by_position]
    if twice:
        raise TypeError("%s() got multiple values for argument '%s'" % (where, twice[0]))
    if len(args) > len(positional) and not any(p.kind == _P.VAR_POSITIONAL for p in parameters):
        least = sum(p.default is _P.empty for p in positional)
        takes = str(least) if least == len(positional) else "from %d to %d" % (least, len(positional))
        raise TypeError("%s() takes %s positional argument%s but %d %s given" % (
            where, takes, "" if takes == "1" else "s", len(args), "was" if len(args) == 1 else "were"))
    if missing:
        raise TypeError("%s() missing required argument '%s'" % (where, missing[0]))
