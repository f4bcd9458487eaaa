"""TOML text for btfsm's policy format (docs/guide/policy-toml.md).

Writes TOML 1.0 basic strings and keys by the TOML specification's escaping
rules (section "String": backslash, quote and the control characters
U+0000..U+001F and U+007F escaped; everything else written as UTF-8), so
that any name a py_trees tree or a SMACH machine holds reads back as itself.
"""

import re

from ._errors import ExportError

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")
_SHORT = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def string(value, what="a name"):
    """A TOML basic string holding `value` exactly."""
    if not isinstance(value, str):
        raise ExportError(f"{what} must be a string, found {type(value).__name__}: {value!r}")
    out = ['"']
    for ch in value:
        code = ord(ch)
        if ch in _SHORT:
            out.append(_SHORT[ch])
        elif code < 0x20 or code == 0x7F:
            out.append(f"\\u{code:04X}")
        elif 0xD800 <= code <= 0xDFFF:
            raise ExportError(f"{what} {value!r} holds a lone surrogate (U+{code:04X}), which TOML cannot hold")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def key(value, what="a key"):
    """A TOML key: bare when it is only letters, digits, `_` and `-`, else quoted."""
    if isinstance(value, str) and _BARE_KEY.match(value):
        return value
    return string(value, what)


def value(v, what="a value"):
    """A TOML value: string, integer, float, boolean, list, or inline table."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v != v:
            return "nan"
        if v in (float("inf"), float("-inf")):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return string(v, what)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(value(x, what) for x in v) + "]"
    if isinstance(v, dict):
        return inline_table(v, what)
    raise ExportError(f"{what}: {type(v).__name__} {v!r} has no TOML form (use a string, number, boolean, list or dict)")


def inline_table(d, what="a table"):
    """`{ k = v, ... }` in the dict's own order."""
    if not d:
        return "{}"
    return "{ " + ", ".join(f"{key(k, what)} = {value(v, what)}" for k, v in d.items()) + " }"
