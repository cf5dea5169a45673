#!/usr/bin/env python3
"""Write docs/validation.md from the validation programs of a build directory.

Builds nothing: runs the tests (CK_FORK=no), the tilt-table example (variants P and R, unwrapped
and --wrapped) and the tilt benchmark of an existing build, collects the tests' `[measured]` lines
and the examples' printed results, and writes one Markdown report.

    python3 tools/validation_report.py [--build-dir build] [--output docs/validation.md]

Each `[measured]` line is traced back to the report() call that printed it (its format string is
matched against the line) and so to the test, or to the helper and the tests that call it; the
setup is the first sentence of the comment above that test or helper. Standard library only.
"""

import argparse
import datetime
import os
import re
import subprocess
import sys
import time

TESTS = ["test_dynamics", "test_contact", "test_web", "test_tilt_table"]
EXAMPLE_RUNS = [
    ("P", False),
    ("P", True),
    ("R", False),
    ("R", True),
]
ANALYTIC_WORDS = r"(?:predicted|expected|analytic|exact|bound|invariants?|theory|discrete|continuous|funicular)"


# ---------------------------------------------------------------- source parsing


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


def comment_before(src, pos):
    """The /* */ block comment ending just before pos (blank space between), or ''."""
    j = pos
    while j > 0 and src[j - 1] in " \t\r\n":
        j -= 1
    if src[j - 2:j] != "*/":
        return ""
    k = src.rfind("/*", 0, j - 2)
    if k < 0:
        return ""
    text = src[k + 2:j - 2]
    text = re.sub(r"^\s*\*+ ?", "", text, flags=re.M)
    return " ".join(text.split())


def first_sentence(text, limit=240):
    if not text:
        return ""
    m = re.search(r"(.+?[.:])(\s|$)", text)
    s = m.group(1) if m else text
    s = s.rstrip(":").strip()
    if len(s) > limit:
        s = s[:limit].rsplit(" ", 1)[0] + " ..."
    return s


DEF_RE = re.compile(r"^(?:START_TEST\((\w+)\)|static\s+[\w\s\*]+?\b(\w+)\s*\([^;{]*\)\s*\{?\s*$)", re.M)


def parse_test_source(path):
    """Report calls of one test file: list of dicts (regex, fmt, func, tests, setup)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            src = fh.read()
    except OSError:
        return []
    defs = []  # (pos, name, is_test)
    for m in DEF_RE.finditer(src):
        if m.group(1):
            defs.append((m.start(), m.group(1), True))
        elif m.group(2) and m.group(2) not in ("report",):
            defs.append((m.start(), m.group(2), False))
    test_bodies = []
    for idx, (pos, name, is_test) in enumerate(defs):
        if is_test:
            end = src.find("END_TEST", pos)
            test_bodies.append((name, src[pos:end if end > 0 else len(src)]))

    def callers(func, seen=None):
        seen = seen or set()
        if func in seen:
            return []
        seen.add(func)
        out = []
        call = re.compile(r"\b" + re.escape(func) + r"\s*\(")
        for tname, body in test_bodies:
            if call.search(body):
                out.append(tname)
        if not out:  # helper of a helper
            for pos, name, is_test in defs:
                if is_test or name == func:
                    continue
                nxt = [p for p, _, _ in defs if p > pos]
                body = src[pos:nxt[0] if nxt else len(src)]
                if call.search(body.split("{", 1)[-1]):
                    out.extend(callers(name, seen))
        return sorted(set(out), key=out.index)

    calls = []
    for m in re.finditer(r"\breport\s*\(", src):
        encl = [d for d in defs if d[0] < m.start()]
        if not encl:
            continue
        pos, name, is_test = encl[-1]
        if name == "report":
            continue
        fmt = c_string_literals(src, m.end())
        if fmt is None:
            continue
        tests = [name] if is_test else callers(name)
        calls.append({
            "regex": format_to_regex(fmt),
            "fmt": fmt,
            "func": name,
            "is_test": is_test,
            "tests": tests,
            "setup": first_sentence(comment_before(src, pos)),
        })
    return calls


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


def split_top(text, seps=(", ", "; ")):
    """Split at separators outside parentheses; also returns each piece's paren groups."""
    pieces, depth, cur, i = [], 0, "", 0
    while i < len(text):
        ch = text[i]
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth = max(0, depth - 1)
        if depth == 0 and any(text.startswith(sp, i) for sp in seps):
            pieces.append(cur)
            cur = ""
            i += 2
            continue
        cur += ch
        i += 1
    if cur:
        pieces.append(cur)
    return [p.strip() for p in pieces if p.strip()]


def paren_groups(text):
    out, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch == "(":
            if depth == 0:
                start = i + 1
            depth += 1
        elif ch == ")" and depth:
            depth -= 1
            if depth == 0:
                out.append(text[start:i])
    return out


def strip_parens(text):
    out, depth = "", 0
    for ch in text:
        if ch == "(":
            depth += 1
        elif ch == ")" and depth:
            depth -= 1
        elif depth == 0:
            out += ch
    return " ".join(out.split())


HAS_NUM = re.compile(r"(?:^|[\s=:])" + NUM + r"(?=$|[\s,;)%])")
ERR_RE = re.compile(r"^(?:diff|rel)\s+" + NUM + r"|^" + NUM + r"\s*%$")


def is_analytic(piece):
    if re.search(r"\b" + ANALYTIC_WORDS + r"\b", piece):
        return True
    lhs = piece.split("=", 1)[0] if "=" in piece else ""
    return bool(lhs) and bool(re.search(r"[()/^*+]| - |\b(?:sqrt|sin|cos|tan|exp|ln|pi)\b", lhs))


def analyse(content):
    """Best-effort split of a measured line into measured / analytical / error."""
    res = {"measured": None, "analytic": None, "error": None}
    clauses = split_top(content)
    mclause = next((c for c in clauses if HAS_NUM.search(strip_parens(c))), None)
    if mclause is not None:
        res["measured"] = strip_parens(mclause)
        for g in paren_groups(mclause):
            for piece in split_top(g):
                if ERR_RE.match(piece) and not res["error"]:
                    res["error"] = piece
                elif not res["analytic"] and HAS_NUM.search(piece) and ("=" in piece or is_analytic(piece)):
                    res["analytic"] = piece
    if not res["analytic"]:
        for c in clauses:
            if c is not mclause and HAS_NUM.search(c) and is_analytic(c):
                res["analytic"] = re.sub(r"\s*\((?:diff|rel)?[^()]*?(?:%|diff [^()]*|rel [^()]*)\)$", "", c)
                for g in paren_groups(c):
                    for piece in split_top(g):
                        if ERR_RE.match(piece) and not res["error"]:
                            res["error"] = piece
                break
    if not res["error"]:
        m = re.search(r"\b(diff|rel)\s+(" + NUM + r")", content) or \
            re.search(r"[(,]\s*(" + NUM + r") ?%[);,]", content)
        if m:
            res["error"] = " ".join(g for g in m.groups() if g) + ("" if m.re.pattern.startswith("\\b") else " %")
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
    for t in TESTS:
        exe = os.path.join(bdir, "tests", t)
        sys.stderr.write("running %s\n" % exe)
        rc, out, err, secs = run([exe], env=env)
        calls = parse_test_source(os.path.join(src, "tests", t + ".c"))
        lines = [l[len("[measured] "):] for l in out.splitlines() if l.startswith("[measured] ")]
        summary = [l for l in out.splitlines() if re.match(r"\d+%: Checks:", l)]
        results = re.findall(r"^[^:\n]+:\d+:([PFE]):[^:\n]*:(\w+):\d+: ?(.*)$", out, re.M)
        failed = [(name, msg) for st, name, msg in results if st != "P"]
        if rc not in (0,) or failed:
            problems.append("%s: exit %s%s" % (t, rc, "; failed: " + ", ".join(n for n, _ in failed) if failed else ""))
        sec = ["## %s" % t, ""]
        sec.append("`CK_FORK=no %s` — %s; exit status %s, %.1f s."
                   % (os.path.relpath(exe, src), summary[-1] if summary else "no summary line", rc, secs))
        if failed:
            sec.append("")
            sec.append("**Failed:** " + "; ".join("`%s`: %s" % (n, md_escape(msg)) for n, msg in failed))
        sec.append("")
        if not lines:
            sec.append("No `[measured]` lines: its checks assert the analytical answers "
                       "(pass/fail only)%s." % (
                           ": " + ", ".join("`%s`" % n for st, n, _ in results) if results else ""))
            sec.append("")
        for line in lines:
            n_cases += 1
            call = next((c for c in calls if c["regex"].match(line)), None)
            label, _, content = line.partition(": ")
            if not content:
                label, content = line, line
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
                sec.append("- Analytical: " + md_escape(a["analytic"]))
            if a["measured"]:
                sec.append("- Measured: " + md_escape(a["measured"]))
            if a["error"]:
                sec.append("- Error: " + md_escape(a["error"]))
            sec.append("- Line: `%s`" % line.replace("`", "'"))
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
    if not args.skip_figures:
        img_dir = os.path.join(os.path.dirname(out_path), "img")
        script = os.path.join(src, "examples", "python", "tilt_table.py")
        lib = os.path.join(bdir, "lib", "libwrapsim.so.0")
        env = dict(os.environ, PYTHONPATH=os.path.join(src, "bindings", "python"),
                   WRAPSIM_LIBRARY=lib)
        cmd = ["/usr/bin/python3", script, "--variant", "R", "--out", img_dir]
        sys.stderr.write("running %s\n" % " ".join(cmd))
        rc, out, err, secs = run(cmd, env=env)
        sec = ["## Figures (examples/python/tilt_table.py, variant R)", ""]
        if rc == 0:
            sec.append("Drawn by `%s` in %.0f s: unwrapped (solid) and wrapped (dashed)."
                       % (" ".join(["python3", os.path.relpath(script, src)] + cmd[2:4]), secs))
            sec.append("")
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
        else:
            sec.append("Not drawn: the script exited with %s (%s)." % (
                rc, md_escape((err.strip().splitlines() or ["no message"])[-1])))
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
            "Each case is one `[measured]` line printed by a validation test (traced to its test "
            "and the setup in the comment above it), or one run of the tilt-table example. "
            "Analytical / Measured / Error are picked out of the line where it gives them; the "
            "line itself is always quoted verbatim. The theory behind the formulas is in "
            "`docs/theory.md`.",
            "",
            "**Summary:** %d cases; %s." % (
                n_cases,
                "problems: " + "; ".join(problems) if problems else "every test program passed and every run finished"),
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
