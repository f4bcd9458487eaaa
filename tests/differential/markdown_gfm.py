#!/usr/bin/env python3
"""Every markdown btfsm writes is inert on GitHub (issue 33): seeded random
hostile strings (backticks, newlines, HTML, links, images, `@` mentions and
teams, e-mail addresses, bare URLs, headings, list and quote markers, table
pipes, entities, invisible and bidirectional characters) are put in the
names each markdown writer shows: `compare --format markdown` (policy
names, node ids, labels, skill arguments, file names), `sim --runs N
--format markdown` (scenario and policy names), `log report --format
markdown` and `log compare --format markdown` (node names, ports, file
names), `review --format markdown` (file names, policy names, node ids,
labels and arguments in a two-commit repository). Each output is rendered by cmark-gfm (PyPI `cmarkgfm`, GitHub's
fork of cmark, with its GitHub extensions: tables, autolinks,
strikethrough, task lists; raw HTML kept, as GitHub keeps it before its
sanitiser) and compared with the output of the same inputs whose strings
are replaced one-to-one by plain names:

- the two renderings hold the same HTML elements, the same number of each
  (inline `code` aside: a string with `@` or a URL is shown as a code span):
  no element, link, image, heading, list, quote or table cell came from an
  input string;
- no text outside `code` and `pre` holds a GitHub mention (`@name`,
  `@org/team`) or an e-mail address.

Usage: markdown_gfm.py --btfsm PATH [--cases N] [--seed S]
"""
import argparse
import html.parser
import json
import random
import re
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import cmarkgfm
from cmarkgfm.cmark import Options

REPO = Path(__file__).resolve().parents[2]

FRAGMENTS = [
    "`", "``", "```", "````", "\n", "\r\n", "\n\n", "\t", "    ", " ",
    "<img src=https://t.example/p.png>", "<details>", "</details>", "<summary>All checks passed</summary>",
    "<script>alert(1)</script>", "<a href=x>", "</td>", "<!--", "-->", "<b>", "<br>",
    "@octocat", "@org/team", " @x", "a@b.co", "mailto:a@b.co", "xmpp:a@b.co",
    "https://evil.example/x", "http://e.example", "www.evil.example", "WWW.E.EXAMPLE/p",
    "[l](https://x.example)", "![i](https://x.example/p.png)", "[r]: https://x.example", "<https://x.example>",
    "# ", "## h", "###### ", "#", "---", "===", "***", "___", "- ", "+ ", "* ", "1. ", "2) ", "> ",
    "|", "\\|", "\\", "*", "_", "~~", "~", "[", "]", "(", ")", "!", ":", "[ ] ", "[x] ",
    "&lt;", "&#64;", "&amp;", "&#x3C;img&#x3E;", ":smile:", "#1", "^", "{", "}",
    "\u200b", "\u200d", "\u202e", "\u2066", "\u00ad", "\u3164", "\ufe0f", "\U000e0041", "\x1b[31m", "\x07",
    "é", "✓", "名", "😀",
]
LETTERS = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-."


def hostile(rng):
    parts = []
    for _ in range(rng.randint(1, 7)):
        if rng.random() < 0.7:
            parts.append(rng.choice(FRAGMENTS))
        else:
            parts.append("".join(rng.choice(LETTERS) for _ in range(rng.randint(1, 6))))
    return "".join(parts)


def toml_str(s):
    out = ['"']
    for c in s:
        o = ord(c)
        if c == '"':
            out.append('\\"')
        elif c == "\\":
            out.append("\\\\")
        elif o < 0x20 or o == 0x7F:
            out.append("\\u%04x" % o)
        elif o > 0xFFFF:
            out.append("\\U%08x" % o)
        else:
            out.append(c)
    out.append('"')
    return "".join(out)


def xml_attr(s):
    # XML 1.0 has no C0 controls but tab, newline and carriage return.
    s = "".join(c if (ord(c) >= 0x20 or c in "\t\n\r") else "?" for c in s)
    return (s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;").replace("\n", "&#10;").replace("\r", "&#13;").replace("\t", "&#9;"))


def file_name(s, ext):
    s = s.replace("/", "_").replace("\0", "_")
    return (s.encode()[:150].decode(errors="ignore") or "x") + ext


class Html(html.parser.HTMLParser):
    """Element counts, and the text outside `code`, `pre` and `a`."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.counts = {}
        self.stack = []
        self.text = []

    def handle_starttag(self, tag, attrs):
        self.counts[tag] = self.counts.get(tag, 0) + 1
        if tag not in ("br", "img", "hr", "input"):
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if tag in self.stack:
            while self.stack and self.stack.pop() != tag:
                pass

    def handle_data(self, data):
        if not any(t in ("code", "pre", "a") for t in self.stack):
            self.text.append(data)


def render(md):
    exts = ["table", "autolink", "strikethrough", "tasklist"]
    return cmarkgfm.markdown_to_html_with_extensions(md, options=Options.CMARK_OPT_UNSAFE, extensions=exts)


# GitHub's mention filter: `@` after the start or a non-word character,
# then a login (and `/team`); an e-mail autolink is `x@y.z`.
MENTION = re.compile(r"(?:^|[^\w`])@[A-Za-z0-9]")
EMAIL = re.compile(r"[\w.+-]@[A-Za-z0-9-]+\.[A-Za-z]")


def check(tag, md_hostile, md_plain, failures):
    h, p = Html(), Html()
    h.feed(render(md_hostile))
    p.feed(render(md_plain))
    ch = {k: v for k, v in h.counts.items() if k != "code"}
    cp = {k: v for k, v in p.counts.items() if k != "code"}
    text = "".join(h.text)
    bad = []
    if ch != cp:
        bad.append(f"elements differ: {ch} vs {cp}")
    if MENTION.search(text) or EMAIL.search(text):
        bad.append("a mention or e-mail address outside code: "
                   + repr((MENTION.search(text) or EMAIL.search(text)).group(0)))
    if bad:
        failures.append((tag, bad, md_hostile))


def run(exe, args, cwd):
    r = subprocess.run([exe] + args, cwd=cwd, capture_output=True, timeout=120)
    return r.returncode, r.stdout.decode("utf-8", "replace")


def bt_policy(name, ids, labels, arg):
    r, a, b = (toml_str(i) for i in ids)
    return f"""kind = "bt"
name = {toml_str(name)}
root = {r}

[nodes]
{r} = {{ sequence = [{a}, {b}] }}
{a} = {{ condition = {toml_str(labels[0])}, skill = "Robot-At", args = {{ target = {toml_str(arg)} }} }}
{b} = {{ action = {toml_str(labels[1])}, skill = "Move-To", args = {{ target = {toml_str(arg)} }} }}
"""


def compare_case(exe, d, s):
    """Strings s[0..9]: names, ids, labels, argument, file names."""
    fa, fb = d / file_name(s[8], ".toml"), d / file_name(s[9], ".toml")
    fa.write_text(bt_policy(s[0], s[2:5], s[5:7], s[7]))
    # b: another name, one node renamed, a label changed.
    fb.write_text(bt_policy(s[1], [s[2], s[3], s[5]], [s[6], s[4]], s[7]))
    return run(exe, ["compare", fa.name, fb.name, "--mode", "named", "--format", "markdown"], d)


def sim_case(exe, d, s):
    shutil.copy(REPO / "policies/paper/fig01-bt.toml", d / "p.toml")
    (d / "s.toml").write_text(f"""name = {toml_str(s[0])}
seed = 1
max_steps = 2000
goal = [{{ if = "Object-At", args = {{ object = "cube2", at = "delivery" }} }}]

[world]
robot = "start"
objects = {{ cube2 = {{ at = "east-table" }} }}

[[policies]]
file = "p.toml"
name = {toml_str(s[1])}

[[policies]]
file = "p.toml"
name = {toml_str(s[2])}
""")
    return run(exe, ["sim", "s.toml", "--runs", "2", "--threads", "1", "--format", "markdown"], d)


def btlog(names, port, records):
    xml = (f'<root BTCPP_format="4"><BehaviorTree ID="M" _fullpath="">'
           f'<Fallback _uid="1" name="{xml_attr(names[0])}">'
           f'<IsOk _uid="2" name="{xml_attr(names[1])}"/>'
           f'<Go _uid="3" name="{xml_attr(names[2])}" to="{xml_attr(port)}"/>'
           f'</Fallback></BehaviorTree><TreeNodesModel><Condition ID="IsOk"/><Action ID="Go"/>'
           f'</TreeNodesModel></root>').encode()
    b = b"BTCPP4-FileLogger2" + bytes([1]) + struct.pack("<i", len(xml)) + xml
    b += struct.pack("<q", 1_700_000_000_000_000)
    for t, uid, st in records:
        b += struct.pack("<Q", t)[:6] + struct.pack("<H", uid) + bytes([st])
    return b


RECORDS = [(0, 1, 1), (1, 2, 3), (2, 3, 1), (5, 3, 2), (6, 1, 2)]


def log_report_case(exe, d, s):
    f = d / file_name(s[4], ".btlog")
    f.write_bytes(btlog(s[0:3], s[3], RECORDS))
    return run(exe, ["log", "report", f.name, "--format", "markdown"], d)


def log_compare_case(exe, d, s):
    a, b = d / file_name(s[5], ".btlog"), d / file_name(s[6], ".btlog")
    a.write_bytes(btlog(s[0:3], s[3], RECORDS))
    b.write_bytes(btlog(s[0:3], s[4], RECORDS))
    return run(exe, ["log", "compare", a.name, b.name, "--format", "markdown"], d)


def git(d, *args):
    env = {"GIT_CONFIG_NOSYSTEM": "1", "HOME": str(d), "PATH": "/usr/bin:/bin:/usr/local/bin"}
    subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@example.org",
                    "-c", "commit.gpgsign=false", *args],
                   cwd=d, env=env, check=True, capture_output=True, timeout=60)


def review_case(exe, d, s):
    """`review --format markdown` of a two-commit repository: a policy file
    (hostile name, ids, labels) changed as compare_case changes it, and
    another added."""
    git(d, "init", "-q", "-b", "main")
    fa, fb = d / file_name(s[8], ".toml"), d / file_name(s[9], ".toml")
    fa.write_text(bt_policy(s[0], s[2:5], s[5:7], s[7]))
    git(d, "add", "-A")
    git(d, "commit", "-q", "-m", "base")
    fa.write_text(bt_policy(s[1], [s[2], s[3], s[5]], [s[6], s[4]], s[7]))
    fb.write_text(bt_policy(s[1], s[2:5], s[5:7], s[7]))
    git(d, "add", "-A")
    git(d, "commit", "-q", "-m", "head")
    return run(exe, ["review", "--base", "HEAD~1", "--head", "HEAD", "--format", "markdown"], d)


WRITERS = [("compare", compare_case, 10), ("sim", sim_case, 3),
           ("log report", log_report_case, 5), ("log compare", log_compare_case, 7),
           ("review", review_case, 10)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--btfsm", required=True)
    ap.add_argument("--cases", type=int, default=60)
    ap.add_argument("--seed", type=int, default=20261123)
    a = ap.parse_args()
    exe = str(Path(a.btfsm).resolve())
    rng = random.Random(a.seed)
    failures, read = [], {w: 0 for w, _, _ in WRITERS}
    for i in range(a.cases):
        for tag, case, n in WRITERS:
            strings = [hostile(rng) for _ in range(n)]
            if len(set(strings)) < n:
                continue
            plain = [f"n{i}x{k}" for k in range(n)]
            with tempfile.TemporaryDirectory() as th, tempfile.TemporaryDirectory() as tp:
                ch, mh = case(exe, Path(th), strings)
                cp, mp = case(exe, Path(tp), plain)
            if cp not in (0, 1):
                sys.exit(f"{tag}: plain names gave exit {cp}:\n{mp}")
            if ch not in (0, 1):
                continue  # the hostile input was refused: nothing rendered
            read[tag] += 1
            check(tag, mh, mp, failures)
    for tag, bad, md in failures[:10]:
        print(f"FAIL {tag}: {'; '.join(bad)}\n{md}\n", file=sys.stderr)
    summary = ", ".join(f"{w} {k}" for w, k in read.items())
    if failures:
        sys.exit(f"markdown_gfm: {len(failures)} outputs with content taken from input ({summary} cases read)")
    if min(read.values()) < a.cases // 4:
        sys.exit(f"markdown_gfm: too few hostile inputs read ({summary}): the test would check nothing")
    print(f"markdown_gfm: {sum(read.values())} markdown outputs of hostile names rendered by cmark-gfm "
          f"with no element, link, mention or heading from input ({summary})")


if __name__ == "__main__":
    main()
