#!/usr/bin/env python3
"""Write docs/validation.md from the validation programs of a build directory.

Builds nothing: runs the Check suites (CK_FORK=no), the tilt-table example (variants P and R,
unwrapped and --wrapped) and the tilt benchmark of an existing build, collects the suites'
`[measured]` lines and the example's printed results, and writes one Markdown report.

    python3 tools/validation_report.py [--build-dir build] [--output docs/validation.md]
                                       [--skip-wrapped] [--skip-figures]

Each `[measured]` line is traced back to the report() call that printed it (its format string is
matched against the line) and so to the test, or to the helper and the tests that call it. From
the test source come the setup (the comment above the test or helper, the comment that opens its
body, or the numbered list of the suite's header comment) and the tolerance: the assertions next
to the report() call that test the reported quantities (they share a variable with its
arguments), each with the comment that argues its size. The line itself gives the measured
figures, the analytical answers and the errors where it prints them. Standard library only.
"""

import argparse
import datetime
import os
import re
import subprocess
import sys
import time

TESTS = ["test_dynamics", "test_contact", "test_contact_clearance", "test_web", "test_tilt_table", "test_law",
         "test_element", "test_detection", "test_drive", "test_implicit", "test_rupture",
         "test_wrap", "test_loadtest", "test_loadtest_runs"]
EXAMPLE_RUNS = [
    ("P", False),
    ("P", True),
    ("R", False),
    ("R", True),
]
ANALYTIC_WORDS = (r"(?:predicted|expected|analytic|exact|bound|invariants?|theory|discrete|"
                  r"continuous|funicular|symplectic|closed|relaxed|instantaneous|Gershgorin|"
                  r"dispersion-corrected)")
TOLERANCE_WORDS = re.compile(r"\b(?:assert\w*|allow\w*|toleran\w*|round-?off|errs?|eps\w*|ulps?|"
                             r"exact\w*|bit for bit|last bit|within|bound\w*|accura\w*)\b", re.I)
TOL_STRONG = re.compile(r"\b(?:toleran\w*|allow\w*|assert\w*)\b", re.I)
MAX_ASSERTS = 6


# ---------------------------------------------------------------- C source model


def c_string_literals(src, pos):
    """Concatenate the adjacent C string literals starting at src[pos:] (after 'report(')."""
    out = []
    i = pos
    n = len(src)
    while i < n:
        while i < n and src[i] in " \t\r\n":
            i += 1
        if i < n and src[i] == '"':
            i += 1
            buf = []
            while i < n and src[i] != '"':
                if src[i] == "\\" and i + 1 < n:
                    esc = src[i + 1]
                    buf.append({"n": "\n", "t": "\t", '"': '"', "\\": "\\"}.get(esc, esc))
                    i += 2
                else:
                    buf.append(src[i])
                    i += 1
            out.append("".join(buf))
            i += 1
        else:
            break
    return "".join(out) if out else None


FMT_SPEC = re.compile(r"%([-+ #0]*)(\d+|\*)?(?:\.(\d+|\*))?(hh|h|ll|l|L|z|j|t)?([diouxXeEfFgGaAcsp%])")


def format_to_regex(fmt):
    """A regex that matches what printf(fmt, ...) prints."""
    parts = []
    last = 0
    for m in FMT_SPEC.finditer(fmt):
        parts.append(re.escape(fmt[last:m.start()]))
        conv = m.group(5)
        if conv == "%":
            parts.append("%")
        elif conv == "s":
            parts.append("(.*?)")
        elif conv == "c":
            parts.append("(.)")
        else:
            parts.append(r"\s*([-+]?(?:[0-9.]+(?:[eE][-+]?\d+)?|inf|nan|0x[0-9a-fA-F]+))")
        last = m.end()
    parts.append(re.escape(fmt[last:]))
    return re.compile("".join(parts) + r"\Z", re.S)


def mask_source(src):
    """src with comments blanked and string/char literal contents blanked (same length), and the
    list of block comments (start, end, inner text)."""
    out = list(src)
    comments = []
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("/*", i):
            k = src.find("*/", i + 2)
            k = n if k < 0 else k + 2
            comments.append((i, k, src[i + 2:k - 2]))
            for p in range(i, k):
                if out[p] != "\n":
                    out[p] = " "
            i = k
        elif src.startswith("//", i):
            k = src.find("\n", i)
            k = n if k < 0 else k
            for p in range(i, k):
                out[p] = " "
            i = k
        elif c in "\"'":
            j = i + 1
            while j < n and src[j] != c and src[j] != "\n":
                j += 2 if src[j] == "\\" else 1
            for p in range(i + 1, min(j, n)):
                out[p] = " "
            i = j + 1
        else:
            i += 1
    return "".join(out), comments


def match_close(code, i):
    """Index just after the bracket that closes code[i] (code is masked)."""
    depth = 0
    for j in range(i, len(code)):
        ch = code[j]
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
            if depth == 0:
                return j + 1
    return len(code)


def split_args(code, src, a, b):
    """Top-level comma-separated pieces of src[a:b] (split where the masked code has commas)."""
    out, depth, start = [], 0, a
    for j in range(a, b):
        ch = code[j]
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == "," and depth == 0:
            out.append((start, j))
            start = j + 1
    out.append((start, b))
    return [(x, y, " ".join(src[x:y].split())) for x, y in out]


def clean_comment(raw, keep_lines=False):
    text = re.sub(r"^[ \t]*\*+ ?", "", raw, flags=re.M)
    return text if keep_lines else " ".join(text.split())


ABBREV = re.compile(r"(?:\b(?:eq|eqs|e\.g|i\.e|Fig|fig|vs|cf|approx|resp|etc|No|no)"
                    r"|(?:^|[;:]\s*)\d{1,2})$")


def sentences(text):
    """Split prose into sentences at '. ' outside parentheses (not after an abbreviation)."""
    out, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch in "([":
            depth += 1
        elif ch in ")]" and depth:
            depth -= 1
        elif ch == "." and depth == 0 and (i + 1 == len(text) or text[i + 1] == " "):
            if (ABBREV.search(text[start:i]) or text[i - 1:i] == ".") and i + 1 < len(text):
                continue
            out.append(text[start:i + 1].strip())
            start = i + 1
    if text[start:].strip():
        out.append(text[start:].strip())
    return out


def first_sentence(text, limit=300):
    """The first sentence (or clause before a top-level ':') of a comment."""
    if not text:
        return ""
    s = sentences(text)[0]
    depth = 0
    for i, ch in enumerate(s):
        if ch in "([":
            depth += 1
        elif ch in ")]" and depth:
            depth -= 1
        elif ch == ":" and depth == 0 and (i + 1 == len(s) or s[i + 1] == " ") and i >= 25:
            s = s[:i]
            break
    s = s.rstrip(":").strip()
    if len(s) > limit:
        s = s[:limit].rsplit(" ", 1)[0] + " ..."
    return s


def numbers_in(text):
    out = []
    for m in re.finditer(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", text):
        try:
            out.append(float(m.group(0)))
        except ValueError:
            pass
    return out


def distinctive(lit):
    """A literal worth looking for in a comment (1e-9, 0.05, 2.5e-4; not 2.0 or 3)."""
    try:
        v = float(lit)
    except ValueError:
        return False
    if v == 0:
        return False
    if "e" in lit.lower():
        return True
    digits = re.sub(r"[^0-9]", "", lit).strip("0")
    return (v != round(v) and len(digits) >= 2) or abs(v) < 0.1


def mentions_number(text, value):
    return any(abs(x - value) <= 1e-12 * max(abs(value), 1e-300) for x in numbers_in(text))


IDENT = re.compile(r"[A-Za-z_]\w*(?:\s*(?:\.|->)\s*[A-Za-z_]\w*)*")
C_WORDS = {"double", "int", "float", "long", "short", "unsigned", "signed", "char", "const",
           "static", "void", "size_t", "uint64_t", "uint32_t", "int64_t", "sizeof", "return",
           "if", "else", "for", "while", "do", "NULL", "true", "false", "struct"}


class Func:
    def __init__(self, name, is_test, start, body_start, body_end):
        self.name, self.is_test = name, is_test
        self.start, self.body_start, self.body_end = start, body_start, body_end


class TestSource:
    """One test file: its functions, comments, report() calls and assertions."""

    DEF_RE = re.compile(r"^(?:START_TEST\s*\(\s*(\w+)\s*\)|static\s+[\w\s\*]+?\b(\w+)\s*\()", re.M)

    def __init__(self, path):
        try:
            with open(path, encoding="utf-8", errors="replace") as fh:
                self.src = fh.read()
        except OSError:
            self.src = ""
        self.code, raw = mask_source(self.src)
        self.comments = []  # (start, end, kind, text)
        for k, (a, b, inner) in enumerate(raw):
            self.comments.append([a, b, *self._kind(inner)])
        for k in range(1, len(self.comments)):  # a short line between two rules is a title
            a, b, kind, text = self.comments[k]
            pa, pb, pkind, _ = self.comments[k - 1]
            if (kind == "text" and pkind == "rule" and not self.src[pb:a].strip()
                    and "\n" not in self.src[a:b] and len(text) < 70 and not text.endswith(".")):
                self.comments[k][2] = "title"
        self.funcs = self._functions()
        self.by_name = {f.name: f for f in self.funcs}
        self.header_items = self._header_items()
        self.calls = self._report_calls()

    # -- comments

    @staticmethod
    def _kind(inner):
        t = clean_comment(inner)
        core = re.sub(r"[=\-]{3,}", " ", t).strip()
        if not core:
            return "rule", ""
        if re.search(r"[=\-]{4,}", t):
            return "title", " ".join(core.split())
        return "text", t

    def _header_items(self):
        """The numbered list of the file's header comment: {"3": "Kelvin-Voigt creep ..."}."""
        if not self.comments or self.comments[0][0] > 200:
            return {}
        body = clean_comment(self.src[self.comments[0][0] + 2:self.comments[0][1] - 2], True)
        items = {}
        for m in re.finditer(r"^\s*(\d+)\.\s+(.*?)(?=^\s*\d+\.\s|^\s*$|\Z)", body, re.M | re.S):
            items[m.group(1)] = " ".join(m.group(2).split()).rstrip(";.")
        return items

    def comments_in(self, a, b, kinds=("text",)):
        return [c for c in self.comments if a <= c[0] and c[1] <= b and c[2] in kinds]

    def comment_above(self, pos):
        """The comment that ends just before pos (blank space between), or None."""
        for c in reversed(self.comments):
            if c[1] <= pos:
                own_line = not self.src[self.src.rfind("\n", 0, c[0]) + 1:c[0]].strip()
                return c if own_line and not self.src[c[1]:pos].strip() else None
        return None

    def _top_level(self, pos):
        return not any(f.body_start <= pos < f.body_end for f in self.funcs)

    def section(self, pos):
        """(title, start) of the section (after the last title comment) holding pos."""
        titles = [c for c in self.comments if c[1] <= pos and c[2] == "title"]
        return (titles[-1][3], titles[-1][1]) if titles else ("", 0)

    def describe(self, func):
        """Setup text of a function, and the comments that may argue its tolerances: its own
        comment, else the one that opens its body, the suite header's item for its numbered
        section, a free-standing comment of its section, or the comment of a helper of its
        section that it calls."""
        above = self.comment_above(func.start)
        own = above[3] if above and above[2] == "text" else ""
        m = re.match(r"\s*\{?\s*", self.src[func.body_start:func.body_end])
        first = next((c for c in self.comments
                      if c[0] == func.body_start + m.end() and c[2] == "text"), None)
        lead = first[3] if first else ""
        title, sec_start = self.section(func.start)
        item = ""
        mnum = re.match(r"(\d+)\.", title)
        if mnum and mnum.group(1) in self.header_items:
            item = self.header_items[mnum.group(1)]
            item = item[0].upper() + item[1:]
        free = ""
        header = self.comments[0] if self.comments and self.comments[0][0] < 200 else None
        for c in self.comments:
            if c is header:
                continue
            own_line = not self.src[self.src.rfind("\n", 0, c[0]) + 1:c[0]].strip()
            if (sec_start <= c[0] and c[1] <= func.start and c[2] == "text" and own_line
                    and self._top_level(c[0])):
                if not any(f.start >= c[1] and not self.src[c[1]:f.start].strip()
                           for f in self.funcs):
                    free = c[3]
                    break
        helper = ""  # a function of its section that it calls or hands over (a callback)
        for h in re.findall(r"\b(\w+)\b", self.code[func.body_start:func.body_end]):
            hf = self.by_name.get(h)
            if hf and not hf.is_test and sec_start <= hf.start < func.start:
                c = self.comment_above(hf.start)
                if c and c[2] == "text":
                    helper = c[3]
                    break
        setup = ""
        for text in (own, lead, item, free, helper, header[3] if header else ""):
            setup = first_sentence(text)
            if setup:
                break
        context = [t for t in (own, free if not own else "", helper if not own else "") if t]
        return setup, context

    # -- functions and calls

    def _functions(self):
        out = []
        code = self.code
        for m in self.DEF_RE.finditer(code):
            if m.group(1):
                p = code.find("(", m.start())
                bs = match_close(code, p)
                be = code.find("END_TEST", bs)
                out.append(Func(m.group(1), True, m.start(), bs, be if be > 0 else len(code)))
            else:
                p = m.end() - 1
                q = match_close(code, p)
                r = q
                while r < len(code) and code[r] in " \t\r\n":
                    r += 1
                if r < len(code) and code[r] == "{":
                    out.append(Func(m.group(2), False, m.start(), r + 1, match_close(code, r) - 1))
        return out

    def statement_range(self, r):
        """End of the statement (block, loop, if, or simple statement) starting at r."""
        code = self.code
        while r < len(code) and code[r] in " \t\r\n":
            r += 1
        if r < len(code) and code[r] == "{":
            return match_close(code, r)
        m = re.match(r"(?:for|while|if)\s*\(", code[r:r + 40])
        if m:
            return self.statement_range(match_close(code, r + m.end() - 1))
        return self.statement_end(r)

    def func_at(self, pos):
        inside = [f for f in self.funcs if f.body_start <= pos < f.body_end]
        return inside[-1] if inside else None

    def statement_end(self, pos):
        j = self.code.find(";", pos)
        return len(self.code) if j < 0 else j + 1

    def callers(self, name, seen=None):
        seen = seen or set()
        if name in seen:
            return []
        seen.add(name)
        call = re.compile(r"\b" + re.escape(name) + r"\s*\(")
        out = [f.name for f in self.funcs if f.is_test
               and call.search(self.code, f.body_start, f.body_end)]
        if not out:
            for f in self.funcs:
                if (not f.is_test and f.name != name
                        and call.search(self.code, f.body_start, f.body_end)):
                    out.extend(self.callers(f.name, seen))
        return sorted(set(out), key=out.index)

    def _report_calls(self):
        calls = []
        for m in re.finditer(r"\breport\s*\(", self.code):
            f = self.func_at(m.start())
            if f is None:
                continue
            p = m.end() - 1
            q = match_close(self.code, p)
            fmt = c_string_literals(self.src, p + 1)
            if fmt is None:
                continue
            args = split_args(self.code, self.src, p + 1, q - 1)[1:]
            convs = [s.group(5) for s in FMT_SPEC.finditer(fmt) if s.group(5) != "%"]
            float_args = [a[2] for a, c in zip(args, convs) if c in "eEfFgGaA"]
            calls.append({
                "regex": format_to_regex(fmt), "fmt": fmt, "func": f.name, "is_test": f.is_test,
                "tests": [f.name] if f.is_test else self.callers(f.name),
                "start": m.start(), "end": self.statement_end(q), "float_args": float_args,
                "args": [a[2] for a in args],
                "f": f,
            })
        for k, c in enumerate(calls):
            c["setup"], c["context"] = self.describe(c["f"])
            prev = [p for p in calls[:k] if p["f"] is c["f"]]
            c["lo"] = prev[-1]["trail"] if prev else c["f"].body_start
            c["trail"] = self.trailing_end(c["end"], c["f"].body_end)
        return calls

    # -- assertions

    ASSERT_RE = re.compile(r"\b(ck_assert\w*)\s*\(")

    def asserts_in(self, a, b):
        out = []
        for m in self.ASSERT_RE.finditer(self.code, a, b):
            macro = m.group(1)
            if re.match(r"ck_assert_(?:int|uint|ptr|str|mem|pstr)_", macro):
                continue
            p = m.end() - 1
            q = match_close(self.code, p)
            args = [x[2] for x in split_args(self.code, self.src, p + 1, q - 1)]
            if macro.endswith("_tol") and len(args) >= 3:
                b = args[1] if re.fullmatch(r"[\w.\[\]>-]+", args[1]) and not args[1].startswith(
                    "-") else "(%s)" % args[1]
                cond = "|%s - %s| <= %s" % (args[0], b, args[2])
            elif re.match(r"ck_assert_(?:double|float|ldouble)_(eq|ne|lt|le|gt|ge)$", macro):
                op = {"eq": "==", "ne": "!=", "lt": "<", "le": "<=", "gt": ">", "ge": ">="}[
                    macro.rsplit("_", 1)[1]]
                cond = "%s %s %s" % (args[0], op, args[1] if len(args) > 1 else "?")
            elif macro in ("ck_assert", "ck_assert_msg") and args:
                cond = args[0]
            else:
                continue
            if re.search(r"\bstrstr\b|\b\w*is_valid\b|\bisnan\b", cond) or not re.search(
                    r"[<>]|==|!=", cond):
                continue
            out.append({"pos": m.start(), "end": self.statement_end(q), "cond": cond,
                        "code": self.code[m.start():q]})
        return out

    def trailing_end(self, pos, limit):
        """End of the assertions (with declarations, ifs and comments) right after pos."""
        code, i, last = self.code, pos, pos
        while True:
            while i < limit and code[i] in " \t\r\n":
                i += 1
            if i >= limit or code[i] == "}":
                break
            rest = code[i:limit]
            m = self.ASSERT_RE.match(rest)
            if m:
                i = self.statement_end(match_close(code, i + m.end() - 1))
                last = i
                continue
            if code[i] == "{":
                i += 1
                continue
            m = re.match(r"(?:if|for|while)\s*\(", rest)
            if m:
                i = match_close(code, i + m.end() - 1)
                continue
            m = re.match(r"else\b", rest)
            if m:
                i += m.end()
                continue
            m = re.match(r"(?:const\s+)?(?:double|int|size_t|long|unsigned|uint64_t)\b[^;{}()]*"
                         r"(?:\([^;{}]*\)[^;{}]*)*;", rest)
            if m:
                i += m.end()
                continue
            break
        return last

    def _idents(self, expr, loopvars):
        out = set()
        for m in IDENT.finditer(expr):
            name = re.sub(r"\s+", "", m.group(0))
            after = expr[m.end():].lstrip()
            if after.startswith("(") or name in C_WORDS or name in loopvars:
                continue
            if re.fullmatch(r"[A-Z][A-Z0-9_]*", name) or name in ("w", "world"):
                continue
            out.add(name)
        return out

    def _assignments(self, f, var):
        """Right-hand sides assigned to var in f's body."""
        base = re.escape(var).replace(r"\.", r"\s*\.\s*")
        rx = re.compile(r"(?<![\w.>])" + base + r"\s*(?:\[[^\]]*\]\s*)?([-+*/]?)=(?!=)")
        out = []
        for m in rx.finditer(self.code, f.body_start, f.body_end):
            if self.code[m.start() - 1:m.start()] in "<>!":
                continue
            a = m.end()
            end = a
            depth = 0
            while end < f.body_end:
                ch = self.code[end]
                if ch in "([{":
                    depth += 1
                elif ch in ")]}":
                    if depth == 0:
                        break
                    depth -= 1
                elif ch in ",;" and depth == 0:
                    break
                end += 1
            out.append((m.group(1), " ".join(self.src[a:end].split())))
        return out

    def tolerance_for(self, call):
        """The assertions on what a report() call prints: list of (cond, why)."""
        f = call["f"]
        lo = call["lo"]
        body = self.code[f.body_start:f.body_end]
        loopvars = set(re.findall(r"\bfor\s*\(\s*(?:int|size_t|long|unsigned)\s+(\w+)", body))
        names = set()
        for a in call["float_args"] or [x for x in call["args"] if not x.startswith('"')]:
            names |= self._idents(a, loopvars)
        helpers = set()
        for v in names:  # a printed variable that a helper computed: that helper's checks
            for op, rhs in self._assignments(f, v):
                helpers |= {h for h in re.findall(r"\b(\w+)\s*\(", rhs) if h in self.by_name
                            and not self.by_name[h].is_test}
        frontier = set(names)
        for _ in range(3):  # a running maximum (worst = fmax(worst, e)) stands for what it takes
            new = set()
            for v in frontier:
                for op, rhs in self._assignments(f, v):
                    toks = self._idents(rhs, loopvars)
                    if op or v in toks:
                        new |= toks
            frontier = new - names
            names |= new
        window = self.asserts_in(lo, call["start"]) + self.asserts_in(call["end"], call["trail"])

        def shares(a):
            toks = {re.sub(r"\s+", "", t) for t in IDENT.findall(a["code"])}
            bases = {t.split(".")[0].split("->")[0] for t in toks}
            return bool(toks & names) or bool(bases & {n for n in names if "." not in n})

        chosen = [(a, f) for a in window if shares(a)]
        if call["trail"] == call["end"]:  # nothing checked right after it: the checks further
            chosen += [(a, f) for a in self.asserts_in(call["end"], f.body_end) if shares(a)]
        if not chosen and names:  # checked before an earlier report() of the function
            chosen = [(a, f) for a in self.asserts_in(f.body_start, f.body_end) if shares(a)]
        if not chosen:  # nothing printed that a check names: the checks with a float tolerance
            chosen = [(a, f) for a in window if FLOAT_LIT.search(a["cond"])]
        for h in sorted(helpers):
            hf = self.by_name[h]
            chosen += [(a, hf) for a in self.asserts_in(hf.body_start, hf.body_end)]
        chosen = chosen[:MAX_ASSERTS]
        return [(pretty_cond(a["cond"]), self.guard(a, fn, call),
                 self.why(a, fn, f, lo if fn is f else fn.body_start)) for a, fn in chosen]

    def checks_of(self, f, limit=3):
        """The assertions with a numeric tolerance in a test that prints nothing."""
        out = []
        for a in self.asserts_in(f.body_start, f.body_end):
            if FLOAT_LIT.search(a["cond"]):
                out.append((pretty_cond(a["cond"]), self.guard(a, f, None),
                            self.why(a, f, f, f.body_start)))
        return out[:limit]

    def guard(self, a, fn, call):
        """('if' or 'unless', condition) of an if/else around the assertion (not the report)."""
        code = self.code
        best = None
        for m in re.finditer(r"\bif\s*\(", code[:fn.body_end]):
            if m.start() < fn.body_start:
                continue
            p = m.end() - 1
            q = match_close(code, p)
            r = q
            while r < len(code) and code[r] in " \t\r\n":
                r += 1
            end = self.statement_range(r)
            ranges = [(r, end, "if", " ".join(self.src[p + 1:q - 1].split()))]
            e = end
            while e < len(code) and code[e] in " \t\r\n":
                e += 1
            if code.startswith("else", e) and not re.match(r"else\s+if\b", code[e:]):
                s2 = e + 4
                while s2 < len(code) and code[s2] in " \t\r\n":
                    s2 += 1
                e2 = self.statement_range(s2)
                ranges.append((s2, e2, "unless", " ".join(self.src[p + 1:q - 1].split())))
            for a0, a1, word, text in ranges:
                inside = a0 <= a["pos"] < a1
                around_report = call is not None and fn is call["f"] and a0 <= call["start"] < a1
                if inside and not around_report and (best is None or a0 > best[0]):
                    best = (a0, word, text)
        return best[1:] if best else None

    def _statement_between(self, a, b):
        """Whether a statement ends between a and b outside the braces opened after a: a comment
        at a then speaks of another statement than the one holding b."""
        paren = brace = 0
        for ch in self.code[a:b]:
            if ch == "(":
                paren += 1
            elif ch == ")":
                paren -= 1
            elif ch == "{":
                brace += 1
            elif ch == "}":
                brace -= 1
                if brace <= 0:
                    return True
            elif ch == ";" and paren <= 0 and brace <= 0:
                return True
        return False

    def _own_line(self, c):
        return not self.src[self.src.rfind("\n", 0, c[0]) + 1:c[0]].strip()

    def why(self, a, fn, caller, lo):
        """The comment that argues an assertion's tolerance: one on the same line; else one
        that quotes its number; else the one right above it; else the nearest one (after lo,
        where the assertions of this report() call begin) or the test's own comment that
        speaks of tolerances."""
        src = self.src
        eol = src.find("\n", a["end"])
        same_line = [c for c in self.comments if a["end"] <= c[0] < (eol if eol > 0 else len(src))]
        if same_line and same_line[0][2] == "text":
            return same_line[0][3]
        found = re.findall(r"(?<![\w.])\d+\.?\d*(?:[eE][-+]?\d+)?", a["cond"])
        lits = [x for x in found if distinctive(x)]
        plain = [x for x in found if not distinctive(x) and float(x) not in (0.0, 1.0)]
        inside = list(reversed(self.comments_in(fn.body_start, a["pos"])))
        context = self.describe(fn)[1]
        for h in re.findall(r"\b(\w+)\s*\(", self.code[caller.body_start:caller.body_end]):
            if h in self.by_name and h not in (caller.name, fn.name):
                c = self.comment_above(self.by_name[h].start)
                if c and c[2] == "text" and c[3] not in context:
                    context.append(c[3])
        near = [c[3] for c in inside] + context
        header = [self.comments[0][3]] if (self.comments and self.comments[0][0] < 200
                                           and self.comments[0][2] == "text") else []
        for lit in lits:
            for text in near + header:
                if mentions_number(text, float(lit)):
                    return excerpt(text, lits)
        above = inside and not self._statement_between(inside[0][1], a["pos"])
        if above and self._own_line(inside[0]):
            return excerpt(inside[0][3], lits)
        for lit in plain:  # 0.3, 2: only where a sentence speaks of a tolerance
            for text in near + header:
                if any(mentions_number(x, float(lit)) and TOL_STRONG.search(x)
                       for x in sentences(text)):
                    return excerpt(text, lits, [lit])
        if above:  # a comment at the end of the line before (if (...) /* why */)
            return excerpt(inside[0][3], lits)
        for text in [c[3] for c in inside if c[0] >= lo] + context[:1]:
            if TOLERANCE_WORDS.search(text):
                return excerpt(text, lits)
        return ""


FLOAT_LIT = re.compile(r"(?<![\w.])(?:\d+\.\d*|\d+(?:\.\d*)?[eE][-+]?\d+)")


def tolerance_lines(tol):
    """Markdown sub-items: the assertions grouped by the comment that argues them."""
    groups = []
    for cond, g, why in tol:
        text = "`%s`%s" % (cond, " (%s `%s`)" % g if g else "")
        for grp in groups:
            if grp[0] == why:
                grp[1].append(text)
                break
        else:
            groups.append([why, [text]])
    return ["  - " + ", ".join(conds) + (": " + md_escape(why) if why else "")
            for why, conds in groups]


def short(text, limit=320):
    if len(text) <= limit:
        return text
    return text[:limit].rsplit(" ", 1)[0] + " ..."


def excerpt(text, lits, plain=(), limit=700):
    """A comment, or from a long one the sentences about the tolerance: those that quote its
    number, else those that speak of assertions or tolerances (with the sentence before one
    that begins with that word)."""
    if len(text) <= 450:
        return text
    ss = sentences(text)
    hits = [i for i, x in enumerate(ss) if any(mentions_number(x, float(v)) for v in lits) or (
        any(mentions_number(x, float(v)) for v in plain) and TOL_STRONG.search(x))]
    if not hits:
        hits = [i for i, x in enumerate(ss) if re.search(r"\b(?:assert\w*|toleran\w*|allow\w*)\b",
                                                          x, re.I)]
    keep = []
    for i in hits:
        if i and re.match(r"(?:\w+ )?(?:assert|allow|toleran)", ss[i], re.I) and i - 1 not in keep:
            keep.append(i - 1)
        if i not in keep:
            keep.append(i)
    out = " ".join(ss[i] for i in sorted(keep)) if keep else " ".join(ss[:2])
    if len(out) > limit:
        out = out[:limit].rsplit(" ", 1)[0] + " ..."
    return out


def pretty_cond(cond):
    """fabs(x) -> |x|, whitespace normalised."""
    cond = " ".join(cond.split())
    while True:
        m = re.search(r"\bfabs\s*\(", cond)
        if not m:
            break
        p = m.end() - 1
        depth = 0
        for j in range(p, len(cond)):
            if cond[j] == "(":
                depth += 1
            elif cond[j] == ")":
                depth -= 1
                if depth == 0:
                    break
        cond = cond[:m.start()] + "|" + cond[p + 1:j] + "|" + cond[j + 1:]
    return cond


# ---------------------------------------------------------------- running


def run(cmd, env=None, timeout=600):
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                           timeout=timeout, universal_newlines=True, errors="replace")
        rc, out, err = p.returncode, p.stdout, p.stderr
    except FileNotFoundError:
        rc, out, err = None, "", "not found: " + cmd[0]
    except subprocess.TimeoutExpired as e:
        rc, out, err = "timeout", (e.stdout or ""), "timed out after %d s" % timeout
        if isinstance(out, bytes):
            out = out.decode("utf-8", "replace")
    return rc, out, err, time.monotonic() - t0


# ---------------------------------------------------------------- line analysis

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
NUM_AT = re.compile(r"(?:^|(?<=[\s=:]))(" + NUM + r")(?=$|[\s,;)%])")
ERR_RE = re.compile(r"^(?:measured\s+)?(?:diff|rel|relative)\s+(" + NUM + r")|^(" + NUM + r")\s*%$")


def depths(text):
    """Bracket depth of each character ( () and [], and inside double quotes )."""
    out, d, q = [], 0, False
    for ch in text:
        if ch == '"':
            q = not q
            out.append(1)
            continue
        if not q and ch in "([":
            out.append(d)
            d += 1
            continue
        if not q and ch in ")]" and d:
            d -= 1
        out.append(d + (1 if q else 0))
    return out


def split_top(text, seps=(", ", "; ")):
    """Split at separators outside brackets and quotes."""
    dep = depths(text)
    pieces, start, i = [], 0, 0
    while i < len(text):
        if dep[i] == 0 and any(text.startswith(sp, i) for sp in seps):
            pieces.append(text[start:i])
            i += 2
            start = i
            continue
        i += 1
    pieces.append(text[start:])
    return [p.strip() for p in pieces if p.strip()]


def top_numbers(text):
    dep = depths(text)
    return [m for m in NUM_AT.finditer(text) if dep[m.start()] == 0]


def paren_spans(text):
    """(start, end) of the top-level parenthesised groups, brackets included."""
    out, d, start, q = [], 0, 0, False
    for i, ch in enumerate(text):
        if ch == '"':
            q = not q
        if q:
            continue
        if ch == "(":
            if d == 0:
                start = i
            d += 1
        elif ch == ")" and d:
            d -= 1
            if d == 0:
                out.append((start, i + 1))
    return out


def is_formula(lhs):
    if "|" in lhs:
        return False
    dep = depths(lhs)
    spaced_paren = any(ch == "(" and i and lhs[i - 1] == " " and dep[i] == 0
                       for i, ch in enumerate(lhs))
    return spaced_paren or bool(re.search(r"[/^*+]| - |\b(?:sqrt|sin|cos|tan|atan|exp|ln|log|pi)\b",
                                          lhs))


def is_analytic(piece):
    if re.match(r"(?:max|min|largest|smallest|worst|mean|measured)\b", piece):
        return False
    if re.search(r"\b" + ANALYTIC_WORDS + r"\b", piece):
        return True
    if "=" in piece:
        lhs = piece.split("=", 1)[0]
        return bool(lhs.strip()) and is_formula(lhs)
    # '2 N T sin(pi/N) 122.088 N': a function of the answer before the figure
    nums = top_numbers(piece)
    lhs = piece[:nums[-1].start()] if nums else ""
    return bool(re.search(r"\b(?:sqrt|sin|cos|tan|atan|exp|ln|log|pi)\b", lhs))


DEVIATION = re.compile(r"\|[^|]*(?: [-+] |[-+]\d)[^|]*\||\b(?:difference|drift|residual|error|"
                       r"deviation|spread|agree|off by)\b")


STRONG = re.compile(r"\b(?:predicted|expected|analytic|exact|theory|would|Gershgorin|"
                    r"dispersion-corrected|invariants?)\b")


def classify(text, first=False):
    """error / tolerance / deviation / analytic / initial / num / text. The first figure of a
    line is what was measured unless its words say otherwise."""
    if ERR_RE.match(text):
        return "error"
    if re.match(r"tolerance\b", text):
        return "tolerance"
    if not top_numbers(text):
        return "text"
    if re.search(r"\bwould\b", text):
        return "analytic"
    if DEVIATION.search(text) or re.match(r"(?:max|largest)\b.* - ", text):
        return "deviation"
    if (STRONG.search(text) and not re.match(r"(?:max|min|largest|measured)\b", text)) if first \
            else is_analytic(text):
        return "analytic"
    if re.match(r"[A-Za-z]\w*0\s*=", text):
        return "initial"
    return "num"


def to_form(head):
    """'<answer> to <number> ...' (at bracket depth 0): the answer, or None."""
    dep = depths(head)
    for m in re.finditer(r"\s(?:to|within)\s+(" + NUM + r")(?=$|[\s,;)%])", head):
        prefix = head[:m.start()]
        if dep[m.start()] == 0 and prefix.strip() and not top_numbers(prefix) and not re.search(
                r"\bup$", prefix):
            return prefix.strip()
    return None


def value_of(text):
    """The one value a 'name = value unit' or 'words value unit' clause gives, or None."""
    if text.count("=") > 1:
        return None
    nums = top_numbers(text.split("=", 1)[1].strip() if "=" in text else text)
    return float(nums[0].group(1)) if len(nums) == 1 else None


def value_unit(text):
    """(value, unit) of a clause that gives one figure ('F(3 s) = 10.0018 N'), else (None, '')."""
    v = value_of(text)
    if v is None:
        return None, ""
    tail = text.split("=", 1)[1] if "=" in text else text
    m = top_numbers(tail.strip())[0]
    return v, tail.strip()[m.end():].strip()


def deviation_value(text):
    """The figure of a deviation clause: after its '=', else its first."""
    nums = top_numbers(text.split("=", 1)[1].strip()) if "=" in text else []
    return (nums or top_numbers(text))[0].group(1)


def split_label(line):
    dep = depths(line)
    for i in range(len(line) - 1):
        if line[i:i + 2] == ": " and dep[i] == 0:
            return line[:i].strip(), line[i + 2:].strip()
    head = split_top(line)[0] if split_top(line) else line
    spans = paren_spans(head)
    for a, b in reversed(spans):
        head = head[:a] + head[b:]
    return " ".join(head.split()), line


def analyse(content):
    """Measured / analytical / error / printed tolerance of a measured line's content."""
    clauses = []
    parts = []
    for c in split_top(content):  # 'measured X vs formula Y': two clauses
        m = re.search(r"\s+vs\.?\s+", c)
        if m and top_numbers(c[:m.start()]) and top_numbers(c[m.end():]):
            parts += [(c[:m.start()], None), (c[m.end():], "analytic")]
        else:
            parts.append((c, None))
    for c, forced in parts:
        nums = top_numbers(c)
        # groups that qualify the clause: not the arguments of sqrt(m/k) or F(0); if it has a
        # figure, the groups after it, else only the groups that hold one
        spans = [(a, b) for a, b in paren_spans(c) if not (a and re.match(r"\w", c[a - 1]))]
        if nums:
            spans = [(a, b) for a, b in spans if a >= nums[0].start()]
        else:
            spans = [(a, b) for a, b in spans if numbers_in(c[a + 1:b - 1])]
        head = c
        for a, b in reversed(spans):
            head = head[:a] + head[b:]
        head = " ".join(head.split())
        pieces = [[classify(p), p] for a, b in spans for p in split_top(c[a + 1:b - 1])]
        head_value, head_unit = value_unit(head)
        for k, p in enumerate(pieces):  # a reference value: followed by its error, or close to
            if p[0] == "num":           # the clause's own figure (in its unit)
                nxt = pieces[k + 1][0] if k + 1 < len(pieces) else ""
                v, unit = value_unit(p[1])
                near = (v is not None and head_value not in (None, 0.0)
                        and abs(v / head_value - 1) <= 0.1 and unit in ("", head_unit))
                if nxt == "error" or near:
                    p[0] = "analytic"
        answer = to_form(head)
        first = not any(x["kind"] in ("num", "measured", "deviation", "analytic")
                        for x in clauses)
        kind = "deviation" if answer is not None else classify(head, first)
        if forced and kind in ("num", "measured", "text"):
            kind = forced
        if answer is not None and not (is_analytic(answer) or re.search(
                r"=|\bfollows\b|\bform\b", answer)):
            answer = ""  # 'nodes agree to 0': a deviation without a stated answer
        if kind == "text" and any(k == "error" for k, _ in pieces):
            kind = "analytic"  # 'symplectic (rel 1e-11)': a reference named, with its error
        clauses.append({"kind": kind, "text": head, "pieces": pieces, "answer": answer})
    seen_measured = False
    for c in clauses:  # after the first figure, one printed with its error is a reference
        if c["kind"] == "num":
            has_err = any(k == "error" for k, _ in c["pieces"])
            c["kind"] = "analytic" if seen_measured and has_err else "measured"
        seen_measured = seen_measured or c["kind"] in ("measured", "deviation")

    res = {"measured": [], "analytic": [], "error": [], "tolerance": [], "computed": [],
           "deviation": False}
    last_value = None
    for c in clauses:
        kind, text = c["kind"], c["text"]
        info = [p for k, p in c["pieces"] if k in ("num", "text", "initial", "measured")]
        if kind == "analytic":
            info = [p for k, p in c["pieces"] if k not in ("error", "tolerance")]
        labelled = text + (" (%s)" % ", ".join(info) if info else "")
        if kind in ("measured", "deviation", "text", "initial"):
            if kind != "initial" or not any(k in ("measured", "deviation") for k in
                                            (x["kind"] for x in clauses)):
                res["measured"].append(labelled)
            last_value = value_of(text) if kind == "measured" else None
        if kind == "deviation":
            res["deviation"] = True
            nums = top_numbers(text)
            if c["answer"] is not None:
                if c["answer"]:
                    res["analytic"].append(c["answer"] + " (the measured figure is the deviation "
                                           "from it)")
                res["error"].append(nums[0].group(1) + " (the measured deviation)")
            else:
                res["error"].append(deviation_value(text) + " (the measured deviation)")
        elif kind == "analytic":
            res["analytic"].append(labelled)
        elif kind == "error":
            res["error"].append(text)
        elif kind == "tolerance":
            res["tolerance"].append(text)
        refs = [text] if kind == "analytic" else []
        has_err = False
        for k, p in c["pieces"]:
            if k == "analytic" and kind != "analytic":
                res["analytic"].append(p)
                refs.append(p)
            elif k == "error":
                res["error"].append(p)
                has_err = True
            elif k == "tolerance":
                res["tolerance"].append(p)
            elif k == "deviation":
                res["deviation"] = True
                res["measured"].append(p)
                res["error"].append(deviation_value(p) + " (the measured deviation)")
        # errors the line does not print: from the printed figures
        for r in ([] if has_err else refs):
            if re.search(r"\b(?:bound|max|min|initial|limit|x_max)\b", r):
                continue
            v = value_of(r)
            if last_value is not None and v not in (None, 0.0) and abs(last_value / v - 1) <= 0.1:
                d = last_value - v
                res["computed"].append("%.3g (rel %.2g) against %s" % (d, d / v, r))
    if not res["measured"] and not res["analytic"]:
        res["measured"].append(content)
    return res


def md_escape(s):
    return s.replace("|", "\\|")


# ---------------------------------------------------------------- examples


def example_errors(text, wrapped, variant):
    """Differences of the example's angles from the theory it prints."""
    notes = []
    th = re.search(r"theory: sliding starts at .*?theta = (" + NUM + r") deg", text)
    tw = re.search(r"theory, wrapped: .*?theta = (" + NUM + r") deg", text)
    for box, ang, t in re.findall(r"^\s*(bottom|top)\s+box: starts to slide at (" + NUM + r") deg \(t = (" + NUM + r") s\)", text, re.M):
        if th and not wrapped:
            d = float(ang) - float(th.group(1))
            notes.append("%s box slides at %s deg: %+.2f deg from tan(theta) = mu (%s deg)"
                         % (box, ang, d, th.group(1)))
    if tw:
        m = re.search(r"passes over the stop's edge at (" + NUM + r") deg", text)
        if m:
            d = float(m.group(1)) - float(tw.group(1))
            notes.append("the load's CoG passes over the stop's edge (the physical tip) at %s deg: "
                         "%+.2f deg from the rigid-stack tipping angle %s deg"
                         % (m.group(1), d, tw.group(1)))
        m = re.search(r"^\s*bottom\s+box: leans > 2 deg on its support from (" + NUM + r") deg", text, re.M)
        if m:
            d = float(m.group(1)) - float(tw.group(1))
            notes.append("stack leans > 2 deg (tips) from %s deg: %+.2f deg from the rigid-stack "
                         "tipping angle %s deg" % (m.group(1), d, tw.group(1)))
    return notes


# ---------------------------------------------------------------- main


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build-dir", default="build", help="meson build directory (default: build)")
    ap.add_argument("--output", default=os.path.join("docs", "validation.md"))
    ap.add_argument("--source-dir", default=root, help="project source tree (default: this tree)")
    ap.add_argument("--skip-wrapped", action="store_true", help="leave out the --wrapped runs")
    ap.add_argument("--skip-figures", action="store_true",
                    help="do not draw the figures (examples/python/tilt_table.py, matplotlib)")
    args = ap.parse_args()
    src = os.path.abspath(args.source_dir)
    bdir = args.build_dir if os.path.isabs(args.build_dir) else os.path.join(src, args.build_dir)
    out_path = args.output if os.path.isabs(args.output) else os.path.join(src, args.output)

    version = "?"
    try:
        with open(os.path.join(src, "meson.build"), encoding="utf-8") as fh:
            m = re.search(r"version\s*:\s*'([^']+)'", fh.read())
            version = m.group(1) if m else "?"
    except OSError:
        pass
    commit = ""
    try:
        commit = subprocess.run(["git", "-C", src, "rev-parse", "--short", "HEAD"],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                universal_newlines=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", src, "status", "--porcelain", "--untracked-files=no"],
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                               universal_newlines=True).stdout.strip()
        if commit and dirty:
            commit += " (with uncommitted changes)"
    except OSError:
        pass

    env = dict(os.environ, CK_FORK="no", CK_VERBOSITY="verbose")
    sections = []
    n_cases = 0
    problems = []
    unmatched_total = 0

    # ---- tests
    n_other = 0
    tol_seen = {}
    for t in TESTS:
        exe = os.path.join(bdir, "tests", t)
        sys.stderr.write("running %s\n" % exe)
        rc, out, err, secs = run([exe], env=env)
        ts = TestSource(os.path.join(src, "tests", t + ".c"))
        lines = [l[len("[measured] "):] for l in out.splitlines() if l.startswith("[measured] ")]
        summary = [l for l in out.splitlines() if re.match(r"\d+%: Checks:", l)]
        results = re.findall(r"^[^:\n]+:\d+:([PFE]):[^:\n]*:(\w+):\d+: ?(.*)$", out, re.M)
        failed = [(name, msg) for st, name, msg in results if st != "P"]
        if rc not in (0,) or failed:
            problems.append("%s: exit %s%s" % (t, rc, "; failed: " + ", ".join(
                n for n, _ in failed) if failed else ""))
        sec = ["## %s" % t, ""]
        sec.append("`CK_FORK=no %s` — %s; exit status %s, %.1f s."
                   % (os.path.relpath(exe, src), summary[-1] if summary else "no summary line",
                      rc, secs))
        if failed:
            sec.append("")
            sec.append("**Failed:** " + "; ".join("`%s`: %s" % (n, md_escape(msg))
                                                  for n, msg in failed))
        sec.append("")
        for line in lines:
            n_cases += 1
            call = next((c for c in ts.calls if c["regex"].match(line)), None)
            label, content = split_label(line)
            a = analyse(content)
            sec.append("### %d. %s" % (n_cases, md_escape(label)))
            sec.append("")
            if call:
                tests = call["tests"] or [call["func"]]
                where = ", ".join("`%s`" % x for x in tests)
                if not call["is_test"]:
                    where += " (through `%s()`)" % call["func"]
                sec.append("- Test: " + where)
                if call["setup"]:
                    sec.append("- Setup: " + md_escape(call["setup"]))
            else:
                unmatched_total += 1
                sec.append("- Test: (no report() call in tests/%s.c matches this line)" % t)
            if a["analytic"]:
                sec.append("- Analytical: " + md_escape("; ".join(a["analytic"])))
            elif a["deviation"]:
                sec.append("- Analytical: 0 (the measured figure is the deviation from the exact "
                           "answer)")
            if a["measured"]:
                sec.append("- Measured: " + md_escape("; ".join(a["measured"])))
            errs = a["error"] + (["from the printed figures: " + "; ".join(a["computed"])]
                                 if a["computed"] else [])
            if errs:
                sec.append("- Error: " + md_escape("; ".join(errs)))
            tol = ts.tolerance_for(call) if call else []
            key = (t, call["start"] if call else None, tuple(tol))
            if tol and key in tol_seen:  # the same checks as an earlier case: name them only
                sec.append("- Tolerance: as in case %d (%s)" % (tol_seen[key], ", ".join(
                    "`%s`%s" % (c, " (%s `%s`)" % g if g else "") for c, g, _ in tol)))
                for s_ in a["tolerance"]:
                    sec.append("  - printed: " + md_escape(s_))
            elif tol or a["tolerance"]:
                tol_seen.setdefault(key, n_cases)
                sec.append("- Tolerance:")
                sec.extend(tolerance_lines(tol))
                for s_ in a["tolerance"]:
                    sec.append("  - printed: " + md_escape(s_))
            else:
                sec.append("- Tolerance: none on these figures (reported; the test's checks "
                           "here are pass/fail)")
            sec.append("- Line: `%s`" % line.replace("`", "'"))
            sec.append("")
        # the tests that print nothing: pass/fail checks of their own
        reported = set()
        for c in ts.calls:
            reported |= set(c["tests"] or [c["func"]])
        others = [f for f in ts.funcs if f.is_test and f.name not in reported]
        if others:
            n_other += len(others)
            bad = {n for n, _ in failed}
            sec.append("### %s: checks without a measured line" % t)
            sec.append("")
            if not lines:
                sec.append("No `[measured]` lines: its checks assert the analytical answers "
                           "(pass/fail only).")
                sec.append("")
            for f in others:
                setup = ts.describe(f)[0]
                state = "failed" if f.name in bad else ("passed" if rc == 0 else "exit %s" % rc)
                item = "- `%s` (%s)" % (f.name, state)
                if setup:
                    item += ": " + md_escape(setup.rstrip("."))
                checks = ts.checks_of(f)
                if checks:
                    item += ". Asserted: " + ", ".join(
                        "`%s`%s" % (c, " (%s `%s`)" % g if g else "") for c, g, _ in checks)
                    why = next((w for _, _, w in checks if w), "")
                    if why:
                        item += " — " + md_escape(short(why))
                sec.append(item)
            sec.append("")
        sections.append("\n".join(sec))

    # ---- the tilt-table example
    ex = os.path.join(bdir, "examples", "tilt_table")
    sec = ["## examples/tilt_table (the paper's benchmark)", ""]
    sec.append("Two cubes (a = 0.25 m, 5 kg) stacked on a plane, static for 1 s, then tilted at "
               "0.1 rad/s; mu = 0.3, v_lim = 10 mm/s, dt = 0.25 ms. Variant P as in the paper "
               "(6 s); R adds a 20 mm stop along the downhill face of the bottom box (7 s). "
               "--wrapped adds the 96 x 61 film band (pre-stretch 40 % / 20 %).")
    sec.append("")
    for variant, wrapped in EXAMPLE_RUNS:
        if wrapped and args.skip_wrapped:
            continue
        cmd = [ex, "--variant", variant] + (["--wrapped"] if wrapped else [])
        sys.stderr.write("running %s\n" % " ".join(cmd))
        rc, out, err, secs = run(cmd)
        n_cases += 1
        name = "variant %s, %s" % (variant, "wrapped" if wrapped else "unwrapped")
        sec.append("### %d. tilt_table %s" % (n_cases, name))
        sec.append("")
        sec.append("`%s` — exit status %s, %.1f s." % (" ".join([os.path.relpath(ex, src)] + cmd[1:]), rc, secs))
        sec.append("")
        theory = [l.strip() for l in out.splitlines() if l.strip().startswith("theory")]
        if theory:
            sec.append("- Analytical: " + "; ".join(md_escape(x) for x in theory))
        notes = example_errors(out, wrapped, variant)
        for n in notes:
            sec.append("- Error: " + md_escape(n))
        if rc != 0:
            problems.append("tilt_table %s: exit %s: %s" % (name, rc, err.strip().splitlines()[-1:] ))
        sec.append("- Measured (printed):")
        sec.append("")
        sec.append("```")
        body = [l for l in out.splitlines() if not l.strip().startswith("theory")]
        sec.extend(body if body else ["(no output)"] + [l for l in err.splitlines()[-3:]])
        sec.append("```")
        sec.append("")
    sections.append("\n".join(sec))

    # ---- figures: the paper's plots from the Python example, embedded where they help
    img_dir = os.path.join(os.path.dirname(out_path), "img")
    script = os.path.join(src, "examples", "python", "tilt_table.py")
    sec = ["## Figures (examples/python/tilt_table.py, variant R)", ""]
    drawn = False
    if not args.skip_figures:
        lib = os.path.join(bdir, "lib", "libwrapsim.so.0")
        env = dict(os.environ, PYTHONPATH=os.path.join(src, "bindings", "python"),
                   WRAPSIM_LIBRARY=lib)
        cmd = ["/usr/bin/python3", script, "--variant", "R", "--out", img_dir]
        sys.stderr.write("running %s\n" % " ".join(cmd))
        rc, out, err, secs = run(cmd, env=env)
        if rc == 0:
            drawn = True
            sec.append("Drawn by `%s` in %.0f s: unwrapped (solid) and wrapped (dashed)."
                       % (" ".join(["python3", os.path.relpath(script, src)] + cmd[2:4]), secs))
        else:
            sec.append("Not drawn: the script exited with %s (%s)." % (
                rc, md_escape((err.strip().splitlines() or ["no message"])[-1])))
    else:
        sec.append("Not redrawn in this run (--skip-figures): the images in `%s/` are those of "
                   "an earlier run of `python3 %s --variant R --out %s`; unwrapped (solid) and "
                   "wrapped (dashed)." % (os.path.relpath(img_dir, src),
                                          os.path.relpath(script, src),
                                          os.path.relpath(img_dir, src)))
    sec.append("")
    if drawn or args.skip_figures:
        for name, what in (("slip.png", "Slip along the platform; the dashed line is the "
                            "theoretical slide time, the dotted one the wrapped stack's tip."),
                           ("cog_distance.png", "Distance between the boxes' CoGs (the "
                            "paper's Fig. 8)."),
                           ("velocities.png", "Speeds of the boxes (the paper's Fig. 9)."),
                           ("snapshots.png", "The stack and the film at three times (the "
                            "paper's Fig. 7).")):
            if os.path.exists(os.path.join(img_dir, name)):
                sec.append("%s" % what)
                sec.append("")
                sec.append("![%s](img/%s)" % (name, name))
                sec.append("")
    sections.append("\n".join(sec))

    # ---- benchmark
    bench = os.path.join(bdir, "bench", "bench_tilt")
    sys.stderr.write("running %s\n" % bench)
    rc, out, err, secs = run([bench])
    sec = ["## bench/bench_tilt (speed, not a pass/fail case)", "",
           "`%s` — exit status %s, %.1f s. Figures depend on the machine and its load." % (
               os.path.relpath(bench, src), rc, secs), "", "```"]
    sec.extend(out.splitlines() or ["(no output)"] + err.splitlines()[-3:])
    sec.append("```")
    sections.append("\n".join(sec))

    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    cmdline = "python3 " + " ".join([os.path.relpath(os.path.abspath(sys.argv[0]), src)] + sys.argv[1:])
    head = ["# libwrapsim — validation report", "",
            "Generated, not typed: `%s` on %s, libwrapsim %s%s, from the programs in `%s/` "
            "(nothing is built by the script). Re-run it after a build to refresh this file."
            % (cmdline, now, version, (", commit " + commit) if commit else "",
               os.path.relpath(bdir, src)),
            "",
            "Each case is one `[measured]` line printed by a validation test (traced to the "
            "report() call that printed it, its test, and the setup in the test's comment), or "
            "one run of the tilt-table example. Analytical / Measured / Error are picked out of "
            "the line where it gives them (an error it does not print is worked out from its "
            "figures); the line itself is always quoted verbatim. Tolerance lists the assertions "
            "on the printed figures, each with the comment in the test that argues its size. "
            "Tests that print nothing are listed after each suite's cases with what they assert. "
            "The theory behind the formulas is in `docs/theory.md`.",
            "",
            "**Summary:** %d cases, and %d checks without a measured line; %s." % (
                n_cases, n_other,
                "problems: " + "; ".join(problems) if problems
                else "every test program passed and every run finished"),
            ""]
    if unmatched_total:
        head.append("%d measured lines could not be traced to a report() call." % unmatched_total)
        head.append("")
    text = "\n".join(head) + "\n" + "\n\n".join(sections) + "\n"
    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    with open(out_path, "w", encoding="utf-8") as fh:
        fh.write(text)
    sys.stderr.write("wrote %s: %d cases\n" % (out_path, n_cases))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
