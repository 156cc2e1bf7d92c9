#!/usr/bin/env python3
"""Cross-checks primm's latency files with an independent HdrHistogram implementation.

For every ``STAGE.hlog`` in a directory (as ``--latency-out DIR`` writes them), the Python
``hdrhistogram`` package (``hdrh``) reads the interval log and decodes every interval; their sum
is then compared with

- ``STAGE.hgrm``: the footer's total count and maximum, and every row's total count (the number
  of decoded samples at or below the row's value);
- optionally primm's printed latency tables (``--tables FILE``: text holding the tables that
  ``primm serve``, ``primm-subscriber`` or ``primm demo`` print): the p50, p90, p99 and p99.9
  of the row of the same name and sample count, recomputed from the decoded samples with
  HdrHistogram's rank rule (the smallest value whose cumulative count reaches ceil(p * total)).

Prints a JSON summary; exits with status 1 and a message naming the file on any mismatch.

    python3 tools/hdr_crosscheck.py DIR [--tables demo-output.txt]
"""

import argparse
import json
import math
import pathlib
import sys

from hdrh.histogram import HdrHistogram
from hdrh.log import HistogramLogReader

# The bounds primm's histograms are recorded with (ns): 1 ns to 60 s, 3 significant digits.
LOWEST_NS = 1
HIGHEST_NS = 60_000_000_000
DIGITS = 3
QUANTILES = (0.5, 0.9, 0.99, 0.999)


class Mismatch(Exception):
    """A file disagrees with the decoded histogram."""


def read_log(path):
    """The sum of every interval of the log at ``path`` and the number of intervals."""
    reference = HdrHistogram(LOWEST_NS, HIGHEST_NS, DIGITS)
    reader = HistogramLogReader(str(path), reference)
    total = HdrHistogram(LOWEST_NS, HIGHEST_NS, DIGITS)
    intervals = 0
    while True:
        interval = reader.get_next_interval_histogram()
        if interval is None:
            break
        intervals += 1
        total.add(interval)
    reader.close()
    return total, intervals


def recorded(histogram):
    """(highest equivalent value, count) of every recorded bucket, in value order."""
    return [
        (histogram.get_highest_equivalent_value(item.value_iterated_to), item.count_at_value_iterated_to)
        for item in histogram.get_recorded_iterator()
    ]


def value_at_quantile(buckets, total, quantile):
    """The smallest bucket value whose cumulative count reaches ceil(quantile * total)."""
    rank = max(1, math.ceil(quantile * total))
    cumulative = 0
    for value, count in buckets:
        cumulative += count
        if cumulative >= rank:
            return value
    return buckets[-1][0]


def parse_hgrm(path):
    """Rows (value µs, percentile, total count) and footer fields of a ``.hgrm`` file."""
    rows, footer = [], {}
    for line in path.read_text().splitlines():
        if line.startswith(("#[Mean", "#[Max", "#[Buckets")):
            for part in line.strip("#[]").split(","):
                key, _, value = part.partition("=")
                footer[key.strip()] = float(value)
            continue
        fields = line.split()
        if not fields or line.startswith("#") or fields[0] == "Value":
            continue
        rows.append((float(fields[0]), float(fields[1]), int(fields[2])))
    return rows, footer


def check_hgrm(path, histogram, buckets):
    rows, footer = parse_hgrm(path)
    total = histogram.get_total_count()
    if int(footer.get("Total count", -1)) != total:
        raise Mismatch(f"{path}: total count {footer.get('Total count')} but the log holds {total}")
    if total == 0:
        return 0
    max_us = histogram.get_max_value() / 1000.0
    if abs(footer["Max"] - max_us) > 0.0005:
        raise Mismatch(f"{path}: Max {footer['Max']} µs but the log's maximum is {max_us} µs")
    if not rows or rows[-1][1] != 1.0 or rows[-1][2] != total:
        raise Mismatch(f"{path}: the last row is not the 100th percentile with every sample")
    for value_us, percentile, count in rows:
        value_ns = round(value_us * 1000.0)
        at_or_below = sum(c for v, c in buckets if v <= value_ns)
        if at_or_below != count:
            raise Mismatch(
                f"{path}: row at {value_us} µs (percentile {percentile}) counts {count}, "
                f"the decoded log {at_or_below}"
            )
        if count < percentile * total - 1e-6 * total - 1:
            raise Mismatch(f"{path}: row at {value_us} µs holds {count} samples, below percentile {percentile}")
    return len(rows)


def parse_tables(text):
    """Rows of primm's latency tables: name -> list of (count, p50, p90, p99, p99.9) in µs."""
    rows = {}
    for line in text.splitlines():
        fields = line.split()
        if len(fields) != 8 or fields[0] == "stage":
            continue
        try:
            count = int(fields[1])
            values = [float(field) for field in fields[2:6]]
        except ValueError:
            continue
        rows.setdefault(fields[0], []).append((count, *values))
    return rows


def check_table(stage, histogram, buckets, table_rows):
    total = histogram.get_total_count()
    candidates = [row for row in table_rows.get(stage, []) if row[0] == total]
    if not candidates:
        return None
    expected = [value_at_quantile(buckets, total, q) / 1000.0 for q in QUANTILES]
    for row in candidates:
        if all(abs(printed - wanted) <= 0.05 + 1e-9 for printed, wanted in zip(row[1:], expected)):
            # hdrh's own percentile (rank rounded instead of rounded up) lands on the same
            # value wherever the two ranks agree.
            for quantile, wanted in zip(QUANTILES, expected):
                if (quantile * total) == int(quantile * total) or round(quantile * total) == math.ceil(quantile * total):
                    own = histogram.get_value_at_percentile(quantile * 100.0) / 1000.0
                    if abs(own - wanted) > 1e-9:
                        raise Mismatch(f"{stage}: hdrh's p{quantile * 100} is {own} µs, the rank rule gives {wanted}")
            return {"stage": stage, "count": total, "p50_us": expected[0], "p99_us": expected[2], "p999_us": expected[3]}
    raise Mismatch(f"{stage}: primm printed {candidates} (count, p50, p90, p99, p99.9 µs); the decoded log gives {expected}")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("directory", type=pathlib.Path)
    parser.add_argument("--tables", type=pathlib.Path, help="text with primm's printed latency tables")
    args = parser.parse_args(argv)
    logs = sorted(args.directory.glob("*.hlog"))
    if not logs:
        print(f"no .hlog file in {args.directory}", file=sys.stderr)
        return 1
    table_rows = parse_tables(args.tables.read_text()) if args.tables else {}
    summary = {"logs": [], "table_rows_checked": []}
    try:
        for log in logs:
            header = log.read_text().splitlines()[:8]
            for wanted in ("#[Histogram log format version 1.3]", "#[StartTime: ", "#[BaseTime: ", '"StartTimestamp"'):
                if not any(line.startswith(wanted) for line in header):
                    raise Mismatch(f"{log}: no line starting with {wanted} in its header")
            if not any("microseconds" in line for line in header):
                raise Mismatch(f"{log}: the header does not state the unit")
            histogram, intervals = read_log(log)
            buckets = recorded(histogram)
            rows = check_hgrm(log.with_suffix(".hgrm"), histogram, buckets)
            summary["logs"].append(
                {"stage": log.stem, "intervals": intervals, "count": histogram.get_total_count(), "hgrm_rows": rows}
            )
            if histogram.get_total_count() > 0 and table_rows:
                checked = check_table(log.stem, histogram, buckets, table_rows)
                if checked:
                    summary["table_rows_checked"].append(checked)
    except Mismatch as mismatch:
        print(f"mismatch: {mismatch}", file=sys.stderr)
        return 1
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
