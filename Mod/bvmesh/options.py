"""Keyword options checked against a compiled function's own signature before it is called: a
misspelt name or a value of the wrong type is named, with the nearest option's name for a typo
(pybind11 answers either with its whole signature, and takes True for a count)."""

import difflib
import numbers
import re

_PARAMETER = re.compile(r"(\w+): ([\w.\[\]]+)")


def _parameters(function):
    """{name: annotated type} from the signature line pybind11 puts first in the docstring."""
    signature = function.__doc__.split("\n", 1)[0]
    return dict(_PARAMETER.findall(signature[signature.index("(") + 1:signature.rindex(")")]))


def check_options(function, caller, options):
    """Raises TypeError naming the first option of `options` that `function` has no parameter for,
    or whose value is not of the parameter's kind (number, integer, text)."""
    parameters = _parameters(function)
    for name, value in options.items():
        kind = parameters.get(name)
        if kind is None:
            near = difflib.get_close_matches(name, parameters, n=1)
            raise TypeError("{} has no option {!r}{}".format(
                caller, name, " (did you mean {!r}?)".format(near[0]) if near else ""))
        if isinstance(value, bool) and kind in ("float", "int"):
            raise TypeError("{}: {} must be a number, got {!r}".format(caller, name, value))
        if kind == "float" and not isinstance(value, numbers.Real):
            raise TypeError("{}: {} must be a number, got {!r}".format(caller, name, value))
        if kind == "int" and not isinstance(value, numbers.Integral):
            raise TypeError("{}: {} must be an integer, got {!r}".format(caller, name, value))
        if kind == "str" and not isinstance(value, str):
            raise TypeError("{}: {} must be a name (text), got {!r}".format(caller, name, value))
