#!/usr/bin/python3
"""promcheck.py: checks Prometheus text-format files (meshcorrd's /metrics
bodies) with Prometheus' own parser (Debian's python3-prometheus-client,
prometheus_client.parser.text_string_to_metric_families) and against the
naming conventions: every family has HELP and TYPE, counters end in _total
and gauges do not, times are _seconds and sizes _bytes, names and labels are
snake_case under the meshcorr_ prefix, no label Prometheus reserves (job,
instance, __*; le only on a histogram's buckets), no series twice, values
numbers (counters finite, >= 0), histograms' buckets cumulative with +Inf
equal to their _count.

usage: promcheck.py FILE... [--expect NAME]...
Prints one line per problem on stderr; exit 0 when there is none, 1 when
there is, 2 when the parser is missing. Test code only (test_daemon_dash
runs it on a real daemon's output)."""
import math
import re
import sys

try:
    from prometheus_client.parser import text_string_to_metric_families
except ImportError as e:
    sys.stderr.write("promcheck: %s (install python3-prometheus-client: "
                     "deploy/install-deps.sh; run with /usr/bin/python3)\n" % e)
    sys.exit(2)

NAME = re.compile(r"^meshcorr_[a-z][a-z0-9]*(_[a-z0-9]+)*$")
LABEL = re.compile(r"^[a-z][a-z0-9]*(_[a-z0-9]+)*$")
RESERVED_LABELS = {"job", "instance", "le", "quantile"}
TIME_WORDS = ("seconds", "elapsed", "uptime", "duration", "latency", "time")
SIZE_WORDS = ("bytes", "memory", "size")


def check_text(path, text, problems, seen_families):
    """Appends the problems of one file to problems; adds its families'
    names (as in the text: counters with _total) to seen_families."""
    def bad(msg):
        problems.append("%s: %s" % (path, msg))

    # What the raw text declares, before the parser munges counter names.
    declared = {}
    helps = set()
    for line in text.splitlines():
        parts = line.split(None, 3)
        if len(parts) >= 3 and parts[0] == "#" and parts[1] == "TYPE":
            if parts[2] in declared:
                bad("TYPE of %s given twice" % parts[2])
            declared[parts[2]] = parts[3] if len(parts) > 3 else ""
        elif len(parts) >= 3 and parts[0] == "#" and parts[1] == "HELP":
            if len(parts) < 4 or not parts[3].strip():
                bad("HELP of %s is empty" % parts[2])
            helps.add(parts[2])
        elif line.startswith("#"):
            bad("comment line that is neither HELP nor TYPE: %r" % line)

    try:
        families = list(text_string_to_metric_families(text))
    except Exception as e:  # the parser refuses the text: that is the finding
        bad("Prometheus' parser refuses the text: %s: %s" % (type(e).__name__, e))
        return
    if not families:
        bad("no metric families")

    series = set()
    for fam in families:
        name = fam.name + ("_total" if fam.type == "counter" else "")
        seen_families.add(name)
        if fam.type in ("untyped", "unknown"):
            bad("%s has no TYPE (or samples outside their family)" % name)
            continue
        if fam.type not in ("counter", "gauge", "histogram"):
            bad("%s has type %s, not counter, gauge or histogram" % (name, fam.type))
        if name not in declared and fam.type == "counter":
            bad("counter %s does not end in _total" % fam.name)
        elif name not in declared:
            bad("%s has no TYPE line of its own" % name)
        if not (helps & {name, fam.name}) or not fam.documentation:
            bad("%s has no HELP" % name)
        if not NAME.match(name):
            bad("%s is not a snake_case name under meshcorr_" % name)
        if fam.type == "gauge" and name.endswith("_total"):
            bad("gauge %s ends in _total, the counters' suffix" % name)
        words = name.split("_")
        if any(w in words for w in TIME_WORDS) and not name.endswith(
                ("_seconds", "_seconds_total")):
            bad("%s is a time but does not end in _seconds" % name)
        if any(w in words for w in SIZE_WORDS) and not name.endswith(
                ("_bytes", "_bytes_total")):
            bad("%s is a size but does not end in _bytes" % name)
        if fam.type == "histogram":
            check_histogram(name, fam.samples, bad)
        for s in fam.samples:
            hist = fam.type == "histogram"
            if s.name != name and not (hist and s.name in (name + "_bucket", name + "_sum", name + "_count")):
                bad("sample %s in family %s" % (s.name, name))
            for k in s.labels:
                if hist and k == "le" and s.name == name + "_bucket":
                    continue
                if k in RESERVED_LABELS or k.startswith("__") or not LABEL.match(k):
                    bad("%s: label %r is reserved by Prometheus or not snake_case"
                        % (name, k))
            key = (s.name, tuple(sorted(s.labels.items())))
            if key in series:
                bad("series %s%s given twice" % (s.name, dict(s.labels)))
            series.add(key)
            if not isinstance(s.value, float):
                bad("%s: value %r is not a number" % (s.name, s.value))
            elif fam.type == "counter" and (not math.isfinite(s.value) or s.value < 0):
                bad("counter %s has value %r" % (s.name, s.value))


def check_histogram(name, samples, bad):
    """Buckets in increasing le, counts cumulative, +Inf last and equal to
    _count; _sum and _count present."""
    buckets = [(s.labels.get("le"), s.value) for s in samples if s.name == name + "_bucket"]
    count = [s.value for s in samples if s.name == name + "_count"]
    if not buckets or buckets[-1][0] != "+Inf":
        bad("histogram %s has no +Inf bucket last" % name)
        return
    if len(count) != 1 or not [s for s in samples if s.name == name + "_sum"]:
        bad("histogram %s lacks _sum or _count" % name)
        return
    bounds = [float(le) for le, _ in buckets]
    if bounds != sorted(bounds):
        bad("histogram %s: buckets not in increasing le" % name)
    values = [v for _, v in buckets]
    if values != sorted(values):
        bad("histogram %s: bucket counts not cumulative" % name)
    if values[-1] != count[0]:
        bad("histogram %s: +Inf bucket %r differs from _count %r" % (name, values[-1], count[0]))


def main(argv):
    files, expect = [], []
    it = iter(argv)
    for a in it:
        if a == "--expect":
            expect.append(next(it, ""))
        else:
            files.append(a)
    if not files:
        sys.stderr.write(__doc__)
        return 2
    problems, seen = [], set()
    for path in files:
        with open(path, encoding="utf-8") as f:
            check_text(path, f.read(), problems, seen)
    for name in expect:
        if name not in seen:
            problems.append("no family %s in any file" % name)
    for p in problems:
        sys.stderr.write("promcheck: %s\n" % p)
    if not problems:
        sys.stderr.write("promcheck: %d file(s), %d families, all well-formed\n"
                         % (len(files), len(seen)))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
