# shellcheck shell=bash
# Counting of meson test results, sourced by tools/quickstart.sh and .ci/run.
#
# meson writes <builddir>/meson-logs/testlog.json with one JSON object per test and line; its
# top-level "result" field is one of OK, EXPECTEDFAIL, SKIP, FAIL, TIMEOUT, ERROR,
# UNEXPECTEDPASS, INTERRUPT. A test's own output sits in the same line as an escaped string
# (\"result\"), which the pattern below does not match, so each line yields its one result.

# count_testlog FILE: print "PASSED FAILED SKIPPED" for FILE; "0 0 0" when FILE does not exist.
# OK and EXPECTEDFAIL count as passed, SKIP as skipped, everything else as failed.
count_testlog() {
    local log=$1
    if [[ ! -f $log ]]; then
        echo "0 0 0"
        return 0
    fi
    awk '
        match($0, /"result": *"[A-Z_]+"/) {
            r = substr($0, RSTART, RLENGTH)
            sub(/^"result": *"/, "", r)
            sub(/"$/, "", r)
            if (r == "OK" || r == "EXPECTEDFAIL") p++
            else if (r == "SKIP") s++
            else f++
        }
        END { printf "%d %d %d\n", p, f, s }
    ' "$log"
}

# format_counts PASSED FAILED SKIPPED: the plain summary line, e.g. "12 passed, 0 failed".
format_counts() {
    local line="$1 passed, $2 failed"
    if (($3 > 0)); then
        line+=", $3 skipped"
    fi
    echo "$line"
}
