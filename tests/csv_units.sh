#!/bin/sh
# Every column of the examples' CSV files names its unit at its end (meson test csv_units).
# Usage: csv_units.sh TILT_TABLE RUBBER_MOUNTS
set -eu
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$1" --duration 0.02 --quiet --csv "$dir/tilt.csv"
"$2" --duration 0.02 --quiet --csv "$dir/mounts.csv"
bad=0
for f in "$dir/tilt.csv" "$dir/mounts.csv"; do
    for col in $(head -n 1 "$f" | tr ',' ' '); do
        case $col in
        *_s | *_m | *_m_s | *_deg | *_N | *_Nm) ;;
        *)
            echo "$(basename "$f"): column '$col' does not end in a unit (_s _m _m_s _deg _N _Nm)"
            bad=1
            ;;
        esac
    done
    echo "$(basename "$f"): $(head -n 1 "$f" | tr ',' '\n' | wc -l) columns"
done
exit $bad
