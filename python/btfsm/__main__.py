"""`python -m btfsm export py_trees|smach MODULE:FACTORY [-o FILE]`.

Imports MODULE (from the current folder or `sys.path`), calls FACTORY()
for the root behaviour / the SMACH StateMachine, and writes btfsm's TOML
(docs/guide/python.md). Exit 0 on success, 2 on an import error or an
ExportError (message on stderr, no file written).
"""

import argparse
import contextlib
import importlib
import os
import sys

from ._errors import ExportError
from ._py_trees import from_py_trees
from ._smach import from_smach


def _load(spec, what):
    module, sep, attr = spec.partition(":")
    if not sep or not module or not attr:
        raise ExportError(f"{what} must be MODULE:NAME, found {spec!r}")
    if "" not in sys.path and os.getcwd() not in sys.path:
        sys.path.insert(0, os.getcwd())
    try:
        obj = importlib.import_module(module)
    except ImportError as e:
        raise ExportError(f"cannot import {module!r}: {e}") from e
    for part in attr.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            raise ExportError(f"module {module!r} has no {attr!r}") from None
    return obj


def _pairs(items, flag):
    out = {}
    for item in items or []:
        k, sep, v = item.rpartition("=")
        if not sep or not k:
            raise ExportError(f"{flag} takes NAME=VALUE, found {item!r}")
        out[k] = v
    return out


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m btfsm", description="Export py_trees trees and SMACH state machines as btfsm TOML.")
    sub = p.add_subparsers(dest="command", required=True)
    e = sub.add_parser("export", help="write btfsm's TOML for a py_trees tree or a SMACH StateMachine")
    e.add_argument("library", choices=["py_trees", "smach"])
    e.add_argument("factory", metavar="MODULE:FACTORY", help="a callable returning the root behaviour or the StateMachine")
    e.add_argument("-o", "--output", metavar="FILE", help="write here (default: standard output)")
    e.add_argument("--name", help="the policy's name")
    e.add_argument("--leaf-kind", action="append", metavar="NAME=action|condition", help="py_trees: a leaf's kind (repeatable)")
    e.add_argument("--ids", metavar="MODULE:NAME", help="py_trees: a {node name: id} mapping or a callable")
    e.add_argument("--decision", action="append", metavar="LABEL", help="smach: a decision state (repeatable)")
    e.add_argument("--strict", action="store_true", help="refuse nodes btfsm can only keep as a generic decorator/control")
    a = p.parse_args(argv)
    try:
        made = _load(a.factory, "MODULE:FACTORY")
        if not callable(made):
            raise ExportError(f"{a.factory} is not callable")
        # Libraries that log with print() (SMACH's smach/log.py) must not
        # mix their lines into the TOML written to standard output.
        with contextlib.redirect_stdout(sys.stderr):
            root = made()
        if a.library == "py_trees":
            ids = _load(a.ids, "--ids") if a.ids else None
            text = from_py_trees(root, leaf_kind=_pairs(a.leaf_kind, "--leaf-kind") or None, ids=ids, strict=a.strict, name=a.name)
        else:
            text = from_smach(root, decision=set(a.decision or []) or None, strict=a.strict, name=a.name)
    except ExportError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    if a.output:
        tmp = a.output + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, a.output)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
