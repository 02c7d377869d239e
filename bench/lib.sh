# Shared by the bench scripts. Sourcing it checks for GNU time and python3 (measure() needs both)
# and defines die(); measure() needs MEASURE_DIR (where GNU time's log and the measured command's
# output go) set before it is called.

# die MESSAGE: the script's name and MESSAGE on stderr, exit 1.
die() { echo "bench/$(basename "$0"): $*" >&2; exit 1; }

[ -x /usr/bin/time ] || die "GNU time is missing: apt-get install time"
command -v python3 >/dev/null || die "python3 is missing"

# measure CMD...: runs CMD under GNU time; prints "wall_s<TAB>cpu_s<TAB>rss_kb" (CPU: user +
# system of CMD and every process it waited for; RSS: the largest one's peak, as time reports it).
measure() {
  local log=$MEASURE_DIR/time.log
  if ! /usr/bin/time -v -o "$log" "$@" >"$MEASURE_DIR/cmd.out" 2>"$MEASURE_DIR/cmd.err"; then
    cat "$MEASURE_DIR/cmd.err" >&2
    die "failed: $*"
  fi
  python3 - "$log" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
wall = re.search(r"Elapsed \(wall clock\) time .*: (\S+)", text).group(1).split(":")
seconds = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
cpu = float(re.search(r"User time \(seconds\): (\S+)", text).group(1)) + \
      float(re.search(r"System time \(seconds\): (\S+)", text).group(1))
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
print(f"{seconds}\t{cpu}\t{rss}")
PY
}

# The load average over 1, 5 and 15 minutes: the scripts print it before and after their runs.
load() { cut -d' ' -f1-3 /proc/loadavg; }
