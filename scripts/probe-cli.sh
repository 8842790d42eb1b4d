#!/usr/bin/env bash
# A probe of the whole flocsim command line with hostile and careless input:
# bad sweep files and case files, bad databases, names full of terminal
# controls, bad Slurm settings (a fake sbatch on PATH), read-only, missing and
# odd paths, symbolic links in --out, truncated results. It follows the
# families of the bad-input rounds (issue 41's twenty items and their kin).
#
# Each probe runs one command under `timeout` and is classified:
#   good  the exit code is the one expected (0 done, 1 failed, 2 input
#         refused, ...) and the output says what was asked for (a pattern
#         naming the field, the value or what is allowed), and
#   bad   anything else, or: it hung (timeout), crashed (a signal, or a raw
#         internal error such as json.exception, std::, stol, terminate),
#         printed a raw control or bidirectional character or bytes that are
#         not UTF-8, or changed or deleted a user file it was not asked to
#         write (each user file's checksum is compared after every probe).
#
# Usage: scripts/probe-cli.sh [BUILD_DIR]   (default build/release)
#   FLOCSIM=path FAKE_WORKER=path override the programs; PROBE_TIMEOUT=s (60)
#   PROBE_KEEP=1 keeps the scratch folder; -v prints every probe's output.
# Prints one line per probe, then the counts by family; exit 0 when every
# probe is good, 1 otherwise.
set -u
verbose=0
[ "${1:-}" = -v ] && verbose=1 && shift
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/release}
F=${FLOCSIM:-$build/apps/flocsim}
FAKE=${FAKE_WORKER:-$build/tests/orchestrator/fake_worker}
T=${PROBE_TIMEOUT:-60}
for p in "$F" "$FAKE"; do
  [ -x "$p" ] || { echo "probe-cli: $p: not built (build the flocsim and fake_worker targets)"; exit 2; }
done
W=$(mktemp -d /tmp/flocsim-probe.XXXXXX)
mounted=()
cleanup() {
  for m in "${mounted[@]+"${mounted[@]}"}"; do umount "$m" 2>/dev/null; done
  chmod -R u+w "$W" 2>/dev/null
  [ "${PROBE_KEEP:-0}" = 1 ] && echo "scratch kept: $W" || rm -rf "$W"
}
trap cleanup EXIT
export FLOCSIM_WORKER= LC_ALL=C.UTF-8
U=$W/user   # the user's own files: never to be changed or deleted by a probe
mkdir -p "$U" "$W/bin"

ESC=$'\e'
RLO=$'\xe2\x80\xae'
C1=$'\xc2\x9b'
BAD=$'\xff\xfe'
LRI=$'\xe2\x81\xa6'

declare -A fam_good fam_bad
families=()
n=0
bad_list=()

checksum_user() { (cd "$U" && find . -type f -print0 | sort -z | xargs -0 -r md5sum) 2>/dev/null; }
user_sums=""
protect() { user_sums=$(checksum_user); }

# Any byte a terminal would obey, or not UTF-8: C0 other than tab and newline,
# DEL, C1 (as UTF-8), the bidirectional controls, invalid UTF-8.
raw_controls() {
  LC_ALL=C grep -qaP '[\x00-\x08\x0b-\x1f\x7f]|\xc2[\x80-\x9f]|\xe2\x80[\x8e\x8f\xa8-\xae]|\xe2\x81[\xa6-\xa9]|\xd8\x9c' "$1" && return 0
  iconv -f UTF-8 -t UTF-8 "$1" >/dev/null 2>&1 || return 0
  return 1
}

# probe FAMILY NAME EXPECT PATTERN [CHECK] -- COMMAND...
#   EXPECT: an exit code (0, 1, 2, 3), "nz" (1 or 2), or "any" (0-3)
#   PATTERN: extended regex the output must match ("" for none)
#   CHECK: shell code that must succeed afterwards (optional)
probe() {
  local fam=$1 name=$2 expect=$3 pat=$4 check=""
  shift 4
  if [ "$1" != -- ]; then check=$1; shift; fi
  shift
  n=$((n + 1))
  local out=$W/out/$n
  mkdir -p "$W/out"
  (cd "${PROBE_CWD:-$W}" && timeout -k 5 "$T" "$@") >"$out" 2>&1 </dev/null
  local rc=$? why=""
  if [ $rc -eq 124 ] || [ $rc -eq 137 ]; then
    why="hung (no answer in $T s)"
  elif [ $rc -gt 3 ]; then
    why="crashed or odd exit $rc"
  elif grep -qaE 'terminate called|json\.exception|what\(\)|Assertion|[^a-z]sto[ild]\b|basic_string|std::|bad_alloc' "$out"; then
    why="raw internal error: $(grep -aEm1 'terminate|json\.exception|what\(\)|std::|sto[ild]|basic_string|bad_alloc|Assert' "$out" | head -c 160)"
  elif raw_controls "$out"; then
    why="raw control, bidi or non-UTF-8 bytes on the terminal"
  elif [ "$expect" = nz ] && { [ $rc -ne 1 ] && [ $rc -ne 2 ]; }; then
    why="exit $rc, expected a refusal (1 or 2)"
  elif [ "$expect" != nz ] && [ "$expect" != any ] && [ $rc -ne "$expect" ]; then
    why="exit $rc, expected $expect"
  elif [ -n "$pat" ] && ! grep -qaE -- "$pat" "$out"; then
    why="output lacks /$pat/"
  elif [ -n "$check" ] && ! (cd "${PROBE_CWD:-$W}" && eval "$check") >/dev/null 2>&1; then
    why="check failed: $check"
  fi
  local now
  now=$(checksum_user)
  if [ -z "$why" ] && [ "$now" != "$user_sums" ]; then
    why="a user file was changed or deleted: $(diff <(echo "$user_sums") <(echo "$now") | grep '^[<>]' | head -2 | tr '\n' ' ')"
  fi
  user_sums=$now
  [ -z "${fam_good[$fam]+x}" ] && families+=("$fam") && fam_good[$fam]=0 && fam_bad[$fam]=0
  local first
  first=$(head -c 400 "$out" | tr '\n' ' ' | LC_ALL=C tr -d '\000-\010\013-\037\177-\377' | cut -c1-150)
  if [ -z "$why" ]; then
    fam_good[$fam]=$((fam_good[$fam] + 1))
    printf 'good %-4s %-12s %s\n' "$n" "$fam" "$name"
  else
    fam_bad[$fam]=$((fam_bad[$fam] + 1))
    bad_list+=("$n $fam $name: $why")
    printf 'BAD  %-4s %-12s %s: %s\n      (rc %s) %s\n' "$n" "$fam" "$name" "$why" "$rc" "$first"
  fi
  if [ $verbose = 1 ]; then sed 's/^/      | /' "$out" | LC_ALL=C tr -d '\000-\010\013-\037\177' | head -20; fi
}

# ---------------------------------------------------------------- fixtures
tiny_fluid() { # viscosity steps
  printf '{"scene":"fluid","fluid":{"size":[16,4,4],"viscosity":%s,"initial":{"type":"shear_wave","amplitude":0.01,"axis":"x","component":"y"}},"run":{"steps":%s,"threads":1,"progress_every_s":1}}' "$1" "$2"
}
tiny_fluid 0.02 40 >"$U/tiny.json"
tiny_fluid 0.04 40 >"$U/tiny04.json"
fake_sweep() { # name [extra fake fields] [axis values]
  printf '{"name":%s,"base":{"x":0,"fake":{"steps":2,"step_ms":5%s}},"axes":{"x":[%s]},"max_attempts":2}' \
    "$1" "${2:-}" "${3:-1,2}"
}
fake_sweep '"f"' >"$U/fake.json"
fake_sweep '"fails"' ',"exit":1' '1' >"$U/fails.json"
printf '{"name":"real","base":%s,"axes":{"fluid.viscosity":[0.02,0.04]}}' "$(tiny_fluid 0.02 40)" >"$U/real.json"
echo "precious" >"$U/precious.txt"
protect

# a results database with one completed fake sweep, and one with a failure
"$F" sweep launch "$U/fake.json" --db "$W/done.db" --worker "$FAKE" >/dev/null 2>&1
"$F" sweep launch "$U/fails.json" --db "$W/failed.db" --worker "$FAKE" >/dev/null 2>&1
protect

L=launch; R=resume
# =========================================================== bad sweep files
fam=sweep-file
bs() { # name pattern json: refused, naming what, before any database is made
  printf '%s' "$3" >"$W/bs.json"
  probe $fam "$1" 2 "$2" '! test -e "$W/bs-'$((n + 1))'.db"' -- "$F" sweep launch "$W/bs.json" --db "$W/bs-$((n + 1)).db" --worker "$FAKE"
}
bs "not JSON" "bs.json.*(JSON|parse|line)" '{"name": "x", '
bs "empty file" "bs.json" ''
bs "an array" "object" '[1,2]'
bs "no name" "name" '{"base":{"x":0},"axes":{"x":[1]}}'
bs "empty name" "name" '{"name":"","base":{"x":0},"axes":{"x":[1]}}'
bs "name with /" "name" '{"name":"a/b","base":{"x":0},"axes":{"x":[1]}}'
bs "name a number" "name" '{"name":5,"base":{"x":0},"axes":{"x":[1]}}'
bs "no base" "base" '{"name":"n","axes":{"x":[1]}}'
bs "base an array" "base" '{"name":"n","base":[],"axes":{"x":[1]}}'
bs "axes a list" "axes" '{"name":"n","base":{"x":0},"axes":[1]}'
bs "axis not a list" "axes|x" '{"name":"n","base":{"x":0},"axes":{"x":1}}'
bs "axis empty list" "x" '{"name":"n","base":{"x":0},"axes":{"x":[]}}'
bs "duplicate axis value" "same case|duplicate|twice" '{"name":"n","base":{"x":0},"axes":{"x":[1,1]}}'
bs "max_attempts 0" "max_attempts" '{"name":"n","base":{"x":0},"axes":{"x":[1]},"max_attempts":0}'
bs "max_attempts -3" "max_attempts" '{"name":"n","base":{"x":0},"axes":{"x":[1]},"max_attempts":-3}'
bs "max_attempts text" "max_attempts" '{"name":"n","base":{"x":0},"axes":{"x":[1]},"max_attempts":"3"}'
bs "max_attempts 1e30" "max_attempts" '{"name":"n","base":{"x":0},"axes":{"x":[1]},"max_attempts":1e30}'
bs "unknown key" "colour|unknown|not" '{"name":"n","base":{"x":0},"axes":{"x":[1]},"colour":"red"}'
bs "huge grid" "runs|grid|[0-9]{6}" '{"name":"n","base":{"x":0},"axes":{"a":[1,2,3,4,5,6,7,8,9,10],"b":[1,2,3,4,5,6,7,8,9,10],"c":[1,2,3,4,5,6,7,8,9,10],"d":[1,2,3,4,5,6,7,8,9,10],"e":[1,2,3,4,5,6,7,8,9,10],"f":[1,2,3,4,5,6,7,8,9,10]}}'
bs "axis path through a number" "x\.y|x" '{"name":"n","base":{"x":0},"axes":{"x.y":[1]}}'
bs "NaN literal" "bs.json" '{"name":"n","base":{"x":NaN},"axes":{"x":[1]}}'
bs "deep nesting" "bs.json|deep|nest" "{\"name\":\"n\",\"base\":$(printf '[%.0s' $(seq 1 3000))$(printf ']%.0s' $(seq 1 3000)),\"axes\":{}}"
bs "slurm not an object" "slurm" '{"name":"n","base":{"x":0},"axes":{"x":[1]},"slurm":5}'
printf '{"name":"n","base":{"scene":"suspension","phi":0.12,"Re_inf":12,"du_over_Uinf":0},"axes":{"seed":[1]},"fidelity":"ultra"}' >"$W/bs.json"
probe $fam "fidelity bogus (plan)" any "fidelity" -- "$F" sweep plan "$W/bs.json" --measure-steps 0
printf '{"name":"n","base":{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":-1},"run":{"steps":1}},"axes":{"run.steps":[1,2]}}' >"$W/bs.json"
probe $fam "a refused case (plan)" 0 "viscosity" -- "$F" sweep plan "$W/bs.json" --measure-steps 0
probe $fam "a refused case (launch)" 1 "viscosity" -- "$F" sweep launch "$W/bs.json" --db "$W/bsr.db"
printf '{"name":"n","base":{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":"v\\u001b[31m\\u202e"},"run":{"steps":1}},"axes":{"run.steps":[1]}}' >"$W/bs.json"
probe $fam "a value with ESC, refused (plan)" 0 "viscosity" -- "$F" sweep plan "$W/bs.json" --measure-steps 0
probe $fam "sweep file missing" 2 "no-such.json" -- "$F" sweep launch "$W/no-such.json" --db "$W/m.db"
probe $fam "sweep file a folder" 2 "folder|directory" -- "$F" sweep launch "$W" --db "$W/m2.db"
probe $fam "sweep file /dev/zero" nz "" -- "$F" sweep plan /dev/zero

# ========================================= 1. a result of another run is not this run's
fam=1-other-result
"$F" run "$U/tiny.json" --out "$W/other" --quiet >/dev/null 2>&1
"$F" sweep launch "$U/real.json" --db "$W/o.db" --worker /bin/false >/dev/null 2>&1
for d in "$W"/o.runs/*/; do cp "$W/other/result.json" "$d"; done
# the 0.02 run's copy is its own result (recorded); the 0.04 run's is not: not
# recorded, no worker started over it, the attempt fails saying what to move
probe $fam "resume with a copied result.json" 1 "another case.*move it out" -- "$F" sweep resume --db "$W/o.db"
own_results() { sqlite3 "$W/o.db" "SELECT count(*) FROM results r JOIN runs u ON u.id = r.run_id WHERE json_extract(r.result_json, '\$.case.fluid.viscosity') = json_extract(u.case_json, '\$.fluid.viscosity')"; }
all_results() { sqlite3 "$W/o.db" "SELECT count(*) FROM results"; }
probe $fam "only the run's own result recorded" any "" 'test "$(own_results)" = 1 && test "$(all_results)" = 1' -- true
probe $fam "run --resume on another case's folder" nz "result.json|another|case" -- "$F" run "$U/tiny04.json" --out "$W/other" --resume --quiet
probe $fam "status after" 0 "completed 1 failed 1" -- "$F" sweep status --db "$W/o.db"
mv "$(sqlite3 "$W/o.db" "SELECT run_dir FROM runs WHERE status = 'failed'")/result.json" "$W/moved.json"
probe $fam "resume after moving it away" 0 "" -- "$F" sweep resume --db "$W/o.db"
probe $fam "each result its own case" any "" 'test "$(own_results)" = 2 && test "$(all_results)" = 2' -- true

# ================================ 2. post leaves out runs with a missing series
fam=2-post-gaps
probe $fam "post tables, no suspension runs" any "" -- "$F" post tables --db "$W/done.db" --out "$W/post1"
probe $fam "post figures, no suspension runs" any "" -- "$F" post figures --db "$W/done.db" --out "$W/post2"
probe $fam "post report, empty database" any "" -- "$F" post report --db "$W/done.db" --out "$W/post3" --sweep nope
probe $fam "post on a missing database" nz "no-such.db" -- "$F" post tables --db "$W/no-such.db" --out "$W/post4"
probe $fam "post --out is a file" nz "precious|file|directory|folder" -- "$F" post tables --db "$W/done.db" --out "$U/precious.txt"

# ======================== 3. truncated result.json, damaged checkpoint
fam=3-truncated
"$F" run "$U/tiny.json" --out "$W/trunc" --quiet >/dev/null 2>&1
head -c 40 "$W/trunc/result.json" >"$W/trunc/r" && mv "$W/trunc/r" "$W/trunc/result.json"
probe $fam "run --resume, truncated result.json" 0 "result.json" -- "$F" run "$U/tiny.json" --out "$W/trunc" --resume
probe $fam "the run completed again" 0 "completed" -- "$F" run "$U/tiny.json" --out "$W/trunc" --resume
mkdir -p "$W/ck" && "$F" run "$U/tiny.json" --out "$W/ck" --quiet --stop-after 5 >/dev/null 2>&1
echo garbage >"$W/ck/checkpoint.h5"
probe $fam "run --resume, damaged checkpoint" nz "checkpoint" -- "$F" run "$U/tiny.json" --out "$W/ck" --resume --quiet
printf '' >"$W/ck/checkpoint.h5"
probe $fam "run --resume, empty checkpoint" nz "checkpoint" -- "$F" run "$U/tiny.json" --out "$W/ck" --resume --quiet
"$F" sweep launch "$U/fake.json" --db "$W/t.db" --worker "$FAKE" >/dev/null 2>&1
for d in "$W"/t.runs/*/; do printf '{"case":' >"$d/result.json"; done
probe $fam "status with truncated results on disk" 0 "completed 2" -- "$F" sweep status --db "$W/t.db"
probe $fam "query with truncated results on disk" 0 "" -- "$F" query --db "$W/t.db"

# ================================== 4. symbolic links in --out
fam=4-links
mkdir -p "$W/lnk"
ln -sf "$U/precious.txt" "$W/lnk/aggregation.csv"
probe $fam "post tables, aggregation.csv a link" nz "link" -- "$F" post tables --db "$W/done.db" --out "$W/lnk"
mkdir -p "$W/elsewhere" && ln -sfn "$W/elsewhere" "$W/lnk2"
probe $fam "post tables, --out a link to a folder" any "" -- "$F" post tables --db "$W/done.db" --out "$W/lnk2/postout"
mkdir -p "$W/lnk3/figures" && ln -sf "$U/precious.txt" "$W/lnk3/figures/figures.gp"
probe $fam "post figures, a script a link" any "" -- "$F" post figures --db "$W/done.db" --out "$W/lnk3"
mkdir -p "$W/runlnk" && ln -sf "$U/precious.txt" "$W/runlnk/result.json"
probe $fam "run --out holding a linked result.json" nz "result.json|link" -- "$F" run "$U/tiny.json" --out "$W/runlnk" --quiet
ln -sfn "$U/precious.txt" "$W/runlnk2"
probe $fam "run --out a link to a file" nz "runlnk2|directory|folder|file" -- "$F" run "$U/tiny.json" --out "$W/runlnk2" --quiet
mkdir -p "$W/runlnk3" && ln -sf "$U/precious.txt" "$W/runlnk3/run.log"
probe $fam "run --out holding a linked run.log" any "" -- "$F" run "$U/tiny.json" --out "$W/runlnk3" --quiet
ln -sf "$U/precious.txt" "$W/dblink.db"
probe $fam "--db a link to a text file" nz "database|SQLite" -- "$F" sweep status --db "$W/dblink.db"
probe $fam "launch into --db a link to a text file" nz "database|SQLite" -- "$F" sweep launch "$U/fake.json" --db "$W/dblink.db" --worker "$FAKE"

# ================================================== 5. Slurm job scripts (fake sbatch)
fam=5-slurm-script
cat >"$W/bin/sbatch" <<EOF
#!/bin/sh
printf '%s\n' "\$@" >> "$W/sbatch.args"
echo 4242
EOF
cat >"$W/bin/squeue" <<'EOF'
#!/bin/sh
case "$*" in *-j*) echo "slurm_load_jobs error: Invalid job id specified"; exit 1;; esac
exit 0
EOF
printf '#!/bin/sh\nexit 0\n' >"$W/bin/sacct"
printf '#!/bin/sh\nexit 0\n' >"$W/bin/scancel"
chmod +x "$W/bin/"*
SP="$W/bin:$PATH"
slurm_launch() { # name sweepname dbdir [expect] [pattern]
  mkdir -p "$3"
  fake_sweep "$2" >"$W/sl.json"
  probe $fam "$1" "${4:-0}" "${5:-submitted|4242|job}" -- env PATH="$SP" "$F" sweep launch "$W/sl.json" --db "$3/s.db" --backend slurm --no-wait --worker "$FAKE"
}
slurm_launch "space in the folder" '"s1"' "$W/with space"
slurm_launch "percent in the name" '"p%j%%x"' "$W/sl2"
slurm_launch "quote in the name" '"q\"x"' "$W/sl3"
slurm_launch "300-character name" "\"$(printf 'n%.0s' $(seq 300))\"" "$W/sl4" any ""
slurm_launch "ESC in the name" '"e\u001b[31m\u202e"' "$W/sl5"
slurm_launch "RLO in the folder" '"r"' "$W/sl6${RLO}x"
probe $fam "the job scripts are valid sh" any "" 'for j in "$W"/sl*/s.runs/slurm/*/job.sh; do sh -n "$j" || exit 1; done' -- true
probe $fam "status of a submitted sweep" 0 "" -- env PATH="$SP" "$F" sweep status --db "$W/sl2/s.db"
probe $fam "cancel of a submitted sweep" 0 "" -- env PATH="$SP" "$F" sweep cancel --db "$W/sl2/s.db"

# =========================================== 6. suggested commands are quoted
fam=6-quoting
for nm in '$(touch${IFS}PWNED)' '`touch${IFS}PWNED`' 'a;touch${IFS}PWNED' "it's" 'a|b' 'x&&touch${IFS}PWNED' 'e$(touch${IFS}PWNED)'$'\e''[31m'; do
  js=$(python3 -c 'import json,sys; print(json.dumps(sys.argv[1]))' "$nm")
  fake_sweep "$js" ',"exit":1' 1 >"$W/q.json"
  rm -f "$W/q.db"*
  "$F" sweep launch "$W/q.json" --db "$W/q.db" --worker "$FAKE" >"$W/q.out" 2>&1
  line=$(grep -a "flocsim sweep resume" "$W/q.out" | head -1 | sed 's/.*\(flocsim sweep resume.*\)/\1/')
  probe $fam "pasted resume line, name $nm" 0 "--sweep" '! test -e "$W/PWNED"' -- sh -c "cd '$W' && echo $line"
done

# ================================ 7. control and bidirectional characters
fam=7-controls
hostile=("red${ESC}[31m" "rlo${RLO}gpj.exe" "c1${C1}2J" "lri${LRI}x" "bell"$'\a' "nl"$'\n'"forged" "bad${BAD}utf8" "title${ESC}]0;pwn"$'\a')
for h in "${hostile[@]}"; do
  if [ "$h" = "bad${BAD}utf8" ]; then  # JSON holds only UTF-8: words on the command line
    probe $fam "stderr, --sweep not UTF-8" 2 "no such sweep" -- "$F" sweep status --db "$W/done.db" --sweep "$h"
    probe $fam "stderr, --db not UTF-8" nz "" -- "$F" query --db "$W/no/$h.db"
    probe $fam "stderr, run case not UTF-8" 2 "" -- "$F" run "$W/$h.json" --out "$W/o"
    continue
  fi
  hj=$(python3 -c 'import json,sys; print(json.dumps(sys.argv[1], ensure_ascii=True))' "$h" 2>/dev/null || echo '"x"')
  tag=$(printf '%s' "$h" | LC_ALL=C tr -c 'a-z0-9' '.' | cut -c1-12)
  printf '{"name":"ctl","base":{"x":1,"label":"","fake":{"steps":1,"step_ms":1}},"axes":{"label":[%s]}}' "$hj" >"$W/c.json"
  rm -rf "$W/c.db"* "$W/c.runs"
  probe $fam "launch, axis value $tag" any "" -- "$F" sweep launch "$W/c.json" --db "$W/c.db" --worker "$FAKE"
  probe $fam "status, axis value $tag" 0 "" -- "$F" sweep status --db "$W/c.db"
  probe $fam "query table, value $tag" 0 "" -- "$F" query --db "$W/c.db" --all
  probe $fam "query csv, value $tag" 0 "" -- "$F" query --db "$W/c.db" --format csv
  probe $fam "stderr, --sweep $tag" 2 "no such sweep" -- "$F" sweep status --db "$W/c.db" --sweep "$h"
  probe $fam "stderr, --db $tag" nz "" -- "$F" query --db "$W/no/$h.db"
done
# the same through a hostile database: names, points, run folders, messages
cp "$W/failed.db" "$W/h.db"
sqlite3 "$W/h.db" "UPDATE sweeps SET name = CAST(X'6e1b5b33316de280ae0a78ffc29b' AS TEXT); UPDATE runs SET error = CAST(X'626f6f6d1b5d303b7469746c6507' AS TEXT), run_dir = run_dir || CAST(X'1b5b324a' AS TEXT); UPDATE sweep_runs SET point_json = CAST(X'7b2278223a22ff227d' AS TEXT);" 2>/dev/null
probe $fam "status of a hostile database" 0 "" -- "$F" sweep status --db "$W/h.db"
probe $fam "query of a hostile database" 0 "" -- "$F" query --db "$W/h.db" --all
probe $fam "query csv of a hostile database" 0 "" -- "$F" query --db "$W/h.db" --format csv
probe $fam "query json of a hostile database" 0 "" -- "$F" query --db "$W/h.db" --format json
probe $fam "resume of a hostile database" any "" -- "$F" sweep resume --db "$W/h.db" --worker "$FAKE"
probe $fam "post tables of a hostile database" any "" -- "$F" post tables --db "$W/h.db" --out "$W/hpost"
probe $fam "cancel of a hostile database" 0 "" -- "$F" sweep cancel --db "$W/h.db"
probe $fam "unknown subcommand with ESC" 2 "no such subcommand" -- "$F" "x${ESC}[2J"
probe $fam "bad option value with ESC" 2 "jobs" -- "$F" sweep launch "$U/fake.json" --db "$W/z.db" --jobs "3${ESC}[2J"
probe $fam "run, missing case with RLO" 2 "" -- "$F" run "$W/c${RLO}.json" --out "$W/o${RLO}"
probe $fam "run, case name with ESC refused" 2 "" -- "$F" run "$W/c.json" --out "$W/x${ESC}[31m"
printf '{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":"v\\u001b[31m\\u202e"},"run":{"steps":1}}' >"$W/cv.json"
probe $fam "run, a field value with ESC" 2 "viscosity" -- "$F" run "$W/cv.json" --out "$W/cvout"

# ==================================== 8. stored Slurm settings are checked
fam=8-stored-slurm
for kv in 'runs_per_task:0' 'runs_per_task:-1' 'cpus_per_task:"eight"' 'max_parallel:-2' 'time_limit:"abc"' 'runs_per_task:1e12' 'partition:5'; do
  k=${kv%%:*} v=${kv#*:}
  cp "$W/failed.db" "$W/st.db"
  spec=$(sqlite3 "$W/st.db" "SELECT spec_json FROM sweeps" 2>/dev/null)
  new=$(printf '%s' "$spec" | python3 -c "import json,sys; s=json.load(sys.stdin); s['slurm']={'$k': json.loads('$v')}; print(json.dumps(s))" 2>/dev/null)
  sqlite3 "$W/st.db" "UPDATE sweeps SET spec_json = '$(printf '%s' "$new" | sed "s/'/''/g")'" 2>/dev/null
  probe $fam "stored slurm.$k = $v" 2 "slurm\.$k" -- env PATH="$SP" "$F" sweep resume --db "$W/st.db" --backend slurm --no-wait --worker "$FAKE"
done
cp "$W/failed.db" "$W/st2.db"; sqlite3 "$W/st2.db" "UPDATE sweeps SET spec_json = 'not json'" 2>/dev/null
probe $fam "stored spec not JSON" nz "spec|stored|JSON" -- env PATH="$SP" "$F" sweep resume --db "$W/st2.db" --backend slurm --no-wait --worker "$FAKE"
probe $fam "stored spec not JSON, local" nz "" -- "$F" sweep resume --db "$W/st2.db" --worker "$FAKE"

# ============================================ 9. slurm.time_limit
fam=9-time-limit
for tl in '"abc"' '"99999999999999999999"' '"-1"' '""' '"01:00:00:00"' '5' '"1-"' '" 1:00"'; do
  printf '{"name":"tl","base":{"x":0,"fake":{"steps":1}},"axes":{"x":[1]},"slurm":{"time_limit":%s}}' "$tl" >"$W/tl.json"
  probe $fam "time_limit $tl" 2 "time_limit" -- env PATH="$SP" "$F" sweep launch "$W/tl.json" --db "$W/tl$n.db" --backend slurm --no-wait --worker "$FAKE"
done
for tl in '"UNLIMITED"' '"1-00:00:00"' '"30"' '"00:10:00"' '"25:00"' '"1:99:00"'; do
  printf '{"name":"tl","base":{"x":0,"fake":{"steps":1}},"axes":{"x":[1]},"slurm":{"time_limit":%s}}' "$tl" >"$W/tl.json"
  probe $fam "time_limit $tl accepted" 0 "" -- env PATH="$SP" "$F" sweep launch "$W/tl.json" --db "$W/tl$n.db" --backend slurm --no-wait --worker "$FAKE"
done
for kv in '"runs_per_task":0' '"cpus_per_task":0' '"cpus_per_task":"2"' '"max_parallel":-1' '"partition":"a b"' '"gres":5' '"colour":1'; do
  printf '{"name":"so","base":{"x":0,"fake":{"steps":1}},"axes":{"x":[1]},"slurm":{%s}}' "$kv" >"$W/so.json"
  probe $fam "slurm option $kv" 2 "slurm" -- env PATH="$SP" "$F" sweep launch "$W/so.json" --db "$W/so$n.db" --backend slurm --no-wait --worker "$FAKE"
done

# ============================================== 10. Slurm commands missing
fam=10-no-sbatch
mkdir -p "$W/onlysq" && cp "$W/bin/squeue" "$W/onlysq/"
probe $fam "sbatch missing, squeue present" nz "sbatch.*(PATH|not)" -- env PATH="$W/onlysq:/usr/bin/env-none" "$F" sweep launch "$U/fake.json" --db "$W/ns.db" --backend slurm --no-wait --worker "$FAKE"
probe $fam "no Slurm at all" nz "squeue|Slurm|slurm" -- env PATH="/nonexistent" "$F" sweep launch "$U/fake.json" --db "$W/ns2.db" --backend slurm --no-wait --worker "$FAKE"
printf '#!/bin/sh\necho "sbatch: error: Batch job submission failed: Invalid partition" >&2\nexit 1\n' >"$W/onlysq/sbatch"; chmod +x "$W/onlysq/sbatch"
probe $fam "sbatch refuses" nz "Invalid partition" -- env PATH="$W/onlysq:$PATH" "$F" sweep launch "$U/fake.json" --db "$W/ns3.db" --backend slurm --no-wait --worker "$FAKE"
printf '#!/bin/sh\nsleep 1000 &\nexec sleep 1000\n' >"$W/onlysq/sbatch"
probe $fam "sbatch never answers: SIGTERM stops flocsim" 1 "stopped" -- sh -c "PATH='$W/onlysq:$PATH' '$F' sweep launch '$U/fake.json' --db '$W/ns4.db' --backend slurm --no-wait --worker '$FAKE' & p=\$!; sleep 3; kill -TERM \$p; wait \$p"
printf '#!/bin/sh\necho "not a job id"\n' >"$W/onlysq/sbatch"
probe $fam "sbatch answers nonsense" nz "job id" -- env PATH="$W/onlysq:$PATH" "$F" sweep launch "$U/fake.json" --db "$W/ns5.db" --backend slurm --no-wait --worker "$FAKE"

# ======================================= 11. low Re_inf at the preset's U_inf
fam=11-low-Re
# a low Re_inf with the preset's U_inf: U_inf is lowered onto the viscosity
# ceiling (0.2) by default, as it is raised onto the stability floor; a
# U_inf given that implies more is refused with the U_inf that would work
for re in 1 0.01; do
  printf '{"scene":"suspension","fidelity":"draft","phi":0.12,"Re_inf":%s,"du_over_Uinf":0}' "$re" >"$W/re.json"
  probe $fam "Re_inf $re: U_inf lowered onto nu 0.2" 0 '"viscosity": 0.2' -- "$F" case check "$W/re.json"
  printf '{"scene":"suspension","fidelity":"draft","phi":0.12,"Re_inf":%s,"du_over_Uinf":0,"numerics":{"U_inf":0.07}}' "$re" >"$W/re.json"
  probe $fam "Re_inf $re with U_inf 0.07" 2 "implies numerics.viscosity.*give numerics.U_inf <=" -- "$F" run "$W/re.json" --out "$W/re$n"
done
for re in 0 -5; do
  printf '{"scene":"suspension","fidelity":"draft","phi":0.12,"Re_inf":%s,"du_over_Uinf":0}' "$re" >"$W/re.json"
  probe $fam "Re_inf $re" 2 "Re_inf = $re: must be > 0" -- "$F" run "$W/re.json" --out "$W/re$n"
done

# ========================================================= 12. --jobs and memory
fam=12-jobs
probe $fam "plan --jobs 4096" 0 "" -- "$F" sweep plan "$U/real.json" --jobs 4096 --measure-steps 1
probe $fam "plan --jobs 0" 2 "jobs" -- "$F" sweep plan "$U/real.json" --jobs 0
probe $fam "plan --jobs -1" 2 "jobs" -- "$F" sweep plan "$U/real.json" --jobs -1
probe $fam "plan --jobs 1e9" 2 "jobs" -- "$F" sweep plan "$U/real.json" --jobs 1000000000
probe $fam "plan --jobs x" 2 "jobs" -- "$F" sweep plan "$U/real.json" --jobs x
probe $fam "plan --measure-steps 5000" 2 "measure-steps" -- "$F" sweep plan "$U/real.json" --measure-steps 5000
probe $fam "plan under a 1 GB address limit" any "" -- sh -c "ulimit -v 1000000; exec '$F' sweep plan '$U/real.json' --jobs 4096 --measure-steps 1"
probe $fam "launch --jobs 64 (fake worker)" 0 "" -- "$F" sweep launch "$U/fake.json" --db "$W/j64.db" --jobs 64 --worker "$FAKE"

# ========================================================= 13. --worker
fam=13-worker
probe $fam "worker missing" 2 "no such file" -- "$F" sweep launch "$U/fake.json" --db "$W/w1.db" --worker "$W/nope"
probe $fam "worker a folder" 2 "directory" -- "$F" sweep launch "$U/fake.json" --db "$W/w2.db" --worker "$W"
probe $fam "worker not executable" 2 "cannot be run|executable" -- "$F" sweep launch "$U/fake.json" --db "$W/w3.db" --worker "$U/precious.txt"
probe $fam "worker not on PATH" 2 "PATH" -- "$F" sweep launch "$U/fake.json" --db "$W/w4.db" --worker no-such-worker-prog
probe $fam "resume, worker missing" 2 "no such file" -- "$F" sweep resume --db "$W/failed.db" --worker "$W/nope"
probe $fam "no database left by refusals" any "" '! test -e "$W/w1.db" && ! test -e "$W/w4.db"' -- true
probe $fam "worker that fails" 1 "exit code 1" -- "$F" sweep launch "$U/fails.json" --db "$W/w5.db" --worker /usr/bin/false
printf '#!/bin/sh\nkill -SEGV $$\n' >"$W/segv.sh"; chmod +x "$W/segv.sh"
probe $fam "worker killed by SIGSEGV" 1 "SIGSEGV|signal" -- "$F" sweep launch "$U/fails.json" --db "$W/w6.db" --worker "$W/segv.sh"
probe $fam "FLOCSIM_WORKER missing" 2 "no such|not found|worker" -- env FLOCSIM_WORKER="$W/nope" "$F" sweep launch "$U/fake.json" --db "$W/w7.db"

# ====================================================== 14. database paths
fam=14-db-path
probe $fam "--db empty" nz "empty" -- "$F" sweep status --db ""
probe $fam "--db a folder" nz "directory" -- "$F" sweep status --db "$W"
probe $fam "--db /dev/null" nz "/dev/null" 'test ! -e /dev/null-journal' -- "$F" sweep launch "$U/fake.json" --db /dev/null --worker "$FAKE"
probe $fam "--db under /proc" nz "/proc" -- "$F" sweep launch "$U/fake.json" --db /proc/self/x.db --worker "$FAKE"
probe $fam "--db through a file" nz "precious.txt" -- "$F" sweep launch "$U/fake.json" --db "$U/precious.txt/x.db" --worker "$FAKE"
probe $fam "--db missing (status)" nz "no-such|exist" -- "$F" sweep status --db "$W/no-such.db"
probe $fam "--db missing (query)" nz "no-such|exist" -- "$F" query --db "$W/no-such.db"
probe $fam "--db missing (resume)" nz "no-such|exist" -- "$F" sweep resume --db "$W/no-such.db" --worker "$FAKE"
probe $fam "--db missing (cancel)" nz "no-such|exist" -- "$F" sweep cancel --db "$W/no-such.db"
probe $fam "--db a text file" nz "precious.txt" -- "$F" query --db "$U/precious.txt"
probe $fam "--db an empty file" nz "empty|database" -- sh -c ": > '$W/empty.db'; exec '$F' query --db '$W/empty.db'"
head -c 3000 "$W/done.db" >"$W/cut.db"
probe $fam "--db a truncated database" nz "cut.db" -- "$F" sweep status --db "$W/cut.db"
probe $fam "--db another SQLite file" nz "no flocsim results|not a flocsim" -- sh -c "sqlite3 '$W/other.sqlite' 'CREATE TABLE t(x)'; exec '$F' query --db '$W/other.sqlite'"
probe $fam "--db newer schema" nz "schema" -- sh -c "cp '$W/done.db' '$W/new.db'; sqlite3 '$W/new.db' 'PRAGMA user_version = 99; UPDATE meta SET value = 99 WHERE key = \"schema_version\"' 2>/dev/null; exec '$F' query --db '$W/new.db'"
probe $fam "--db folder missing (launch makes it)" 0 "no/such" -- "$F" sweep launch "$U/fake.json" --db "$W/no/such/x.db" --worker "$FAKE"
probe $fam "--runs-dir a file" nz "precious|runs" -- "$F" sweep launch "$U/fake.json" --db "$W/rd.db" --runs-dir "$U/precious.txt" --worker "$FAKE"
probe $fam "--db with a newline" nz "" -- "$F" sweep status --db "$W/a"$'\n'"b.db"
if [ "$(id -u)" = 0 ]; then
  mkdir -p "$W/ro" "$W/rosrc" && cp "$W/done.db" "$W/rosrc/d.db"
  if mount --bind "$W/rosrc" "$W/ro" 2>/dev/null && mount -o remount,ro,bind "$W/ro" 2>/dev/null; then
    mounted+=("$W/ro")
    probe $fam "read-only: status" 0 "read-only" -- "$F" sweep status --db "$W/ro/d.db"
    probe $fam "read-only: query" 0 "" -- "$F" query --db "$W/ro/d.db"
    probe $fam "read-only: cancel (only reads)" 0 "nothing is running" -- "$F" sweep cancel --db "$W/ro/d.db"
    probe $fam "read-only: resume" nz "read-only" -- "$F" sweep resume --db "$W/ro/d.db" --worker "$FAKE"
    probe $fam "read-only: launch" nz "read-only" -- "$F" sweep launch "$U/fake.json" --db "$W/ro/d.db" --worker "$FAKE"
    probe $fam "read-only: new db in the folder" nz "ro" -- "$F" sweep launch "$U/fake.json" --db "$W/ro/n.db" --worker "$FAKE"
    probe $fam "read-only: run --out" nz "ro" -- "$F" run "$U/tiny.json" --out "$W/ro/run" --quiet
    probe $fam "read-only: post --out" nz "ro" -- "$F" post tables --db "$W/done.db" --out "$W/ro/post"
  fi
fi

# =============================================================== 15. full disk
fam=15-disk-full
if [ "$(id -u)" = 0 ] && mkdir -p "$W/full" && mount -t tmpfs -o size=600k tmpfs "$W/full" 2>/dev/null; then
  mounted+=("$W/full")
  cp "$W/done.db" "$W/full/d.db" 2>/dev/null
  head -c 2000000 /dev/zero >"$W/full/fill" 2>/dev/null
  probe $fam "status on a full disk" 0 "full" -- "$F" sweep status --db "$W/full/d.db"
  probe $fam "query on a full disk" 0 "" -- "$F" query --db "$W/full/d.db"
  probe $fam "resume on a full disk" nz "full|space" -- "$F" sweep resume --db "$W/full/d.db" --worker "$FAKE"
  probe $fam "launch on a full disk" nz "full|space" -- "$F" sweep launch "$U/fake.json" --db "$W/full/n.db" --worker "$FAKE"
  probe $fam "run --out on a full disk" nz "full|space|write" -- "$F" run "$U/tiny.json" --out "$W/full/run" --quiet
  probe $fam "post --out on a full disk" nz "full|space|write" -- "$F" post tables --db "$W/done.db" --out "$W/full/post"
fi

# =========================================== 16. post options checked first
fam=16-post-options
probe $fam "report --columns bogus" 2 "bogus" '! test -e "$W/p16/aggregation.csv"' -- "$F" post report --db "$W/done.db" --out "$W/p16" --columns bogus
probe $fam "tables --columns empty" 2 "" -- "$F" post tables --db "$W/done.db" --out "$W/p17" --columns ""
probe $fam "tables --where bad" 2 "where|OP|filter" -- "$F" post tables --db "$W/done.db" --out "$W/p18" --where "phi ~ 3"
probe $fam "query --columns bogus" 2 "bogus" -- "$F" query --db "$W/done.db" --columns bogus
probe $fam "query --where no operator" 2 "where|OP" -- "$F" query --db "$W/done.db" --where phi
probe $fam "query --where NaN" any "" -- "$F" query --db "$W/done.db" --where "x < nan"
probe $fam "query --where unknown field" any "" -- "$F" query --db "$W/done.db" --where "nope = 1"
probe $fam "query --format xml" 2 "format" -- "$F" query --db "$W/done.db" --format xml
probe $fam "query --sweep unknown" 2 "nope" -- "$F" query --db "$W/done.db" --sweep nope
probe $fam "post figures --columns (not an option)" 2 "columns" -- "$F" post figures --db "$W/done.db" --out "$W/p19" --columns F

# ===================================== 17. relative positions_from in a sweep
fam=17-positions
mkdir -p "$W/s17/sub"
printf '{"name":"pf","base":{"scene":"fixed-array","fidelity":"draft","Re_inf":12,"du_over_Uinf":0,"positions_from":"snap.h5"},"axes":{"seed":[1]}}' >"$W/s17/sub/pf.json"
probe $fam "relative positions_from, missing beside the sweep" nz "s17/sub/snap.h5" -- "$F" sweep launch "$W/s17/sub/pf.json" --db "$W/s17/pf.db"
PROBE_CWD=$W/s17 probe $fam "from another folder (plan)" any "s17/sub/snap.h5" -- "$F" sweep plan sub/pf.json
printf 'not hdf5' >"$W/s17/sub/snap.h5"
probe $fam "positions_from not HDF5" nz "snap.h5" -- "$F" sweep launch "$W/s17/sub/pf.json" --db "$W/s17/pf2.db"

# ====================================== 18. granular scene with coupling options
fam=18-granular
for extra in '"numerics":{"immersed_boundary":{"forcing":"control"}}' '"numerics":{"coupling":"partially-saturated"}' '"lubrication_model":"calibrated"'; do
  printf '{"scene":"granular","fidelity":"draft","phi":0.2,"Re_inf":12,"du_over_Uinf":0.5,%s,"protocol":{"stage1_min":1,"stage1_max":1,"stage2_settle":0.5,"statistics":1,"sample_every":0.05}}' "$extra" >"$W/g.json"
  # named (a warning, as the user guide says) rather than silently taken
  probe $fam "granular with $extra" any "granular|no liquid" -- "$F" run "$W/g.json" --out "$W/g$n"
done

# ================================================== 19. control gains as given
fam=19-gains
for g in '{"integral":1,"proportional":1.0000001}' '{"integral":0.5,"proportional":0}' '{"integral":"1","proportional":0}' '{"integral":1e400,"proportional":0}' '[1,1]'; do
  printf '{"scene":"suspension","fidelity":"draft","phi":0.12,"Re_inf":12,"du_over_Uinf":0,"numerics":{"immersed_boundary":{"forcing":"control","gains":%s}}}' "$g" >"$W/gn.json"
  probe $fam "gains $g" 2 "gains" -- "$F" run "$W/gn.json" --out "$W/gn$n"
done
printf '{"scene":"suspension","fidelity":"draft","phi":0.12,"Re_inf":12,"du_over_Uinf":0,"numerics":{"immersed_boundary":{"forcing":"control","sweeps":2}}}' >"$W/gs.json"
probe $fam "sweeps 2 with control forcing" 2 "control" -- "$F" run "$W/gs.json" --out "$W/gs"
probe $fam "calibrate --gains 1,1.0000001" 2 "1.0000001" -- "$F" calibrate --radius 4 --forcing control --gains 1,1.0000001 --table "$W/cal.json"

# ========================================= 20. snapshot_every 0 and cancel
fam=20-promises
printf '{"scene":"granular","fidelity":"draft","phi":0.2,"Re_inf":12,"du_over_Uinf":0.5,"protocol":{"stage1_min":1,"stage1_max":1,"stage2_settle":0.5,"statistics":1,"sample_every":0.05,"snapshot_every":0}}' >"$W/s0.json"
probe $fam "snapshot_every 0 writes none" 0 "" '! ls "$W"/s0/spheres/step_* >/dev/null 2>&1' -- "$F" run "$W/s0.json" --out "$W/s0" --quiet
sed 's/"snapshot_every":0/"snapshot_every":-1/' "$W/s0.json" >"$W/s1.json"
probe $fam "snapshot_every -1" 2 "snapshot_every" -- "$F" run "$W/s1.json" --out "$W/s0b" --quiet
probe $fam "cancel with nothing running" 0 "nothing is running" -- "$F" sweep cancel --db "$W/done.db"

# ======================================================= run: bad case files
fam=run-case
rc_() { printf '%s' "$3" >"$W/rc.json"; probe $fam "$1" 2 "$2" -- "$F" run "$W/rc.json" --out "$W/rc$n" --quiet; }
rc_ "empty case" "rc.json" ''
rc_ "not JSON" "rc.json" '{"scene":'
rc_ "no scene" "scene" '{}'
rc_ "unknown scene" "scene" '{"scene":"plasma"}'
rc_ "scene a number" "scene" '{"scene":3}'
rc_ "negative size" "size" '{"scene":"fluid","fluid":{"size":[-8,4,4],"viscosity":0.02},"run":{"steps":1}}'
rc_ "size 1e12" "size" '{"scene":"fluid","fluid":{"size":[1000000000000,4,4],"viscosity":0.02},"run":{"steps":1}}'
rc_ "size not a list" "size" '{"scene":"fluid","fluid":{"size":8,"viscosity":0.02},"run":{"steps":1}}'
rc_ "viscosity 0" "viscosity" '{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":0},"run":{"steps":1}}'
rc_ "viscosity huge" "viscosity" '{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":1e300},"run":{"steps":1}}'
rc_ "steps -1" "steps" '{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":0.02},"run":{"steps":-1}}'
rc_ "steps 2.5" "steps" '{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":0.02},"run":{"steps":2.5}}'
rc_ "steps 1e20" "steps" '{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":0.02},"run":{"steps":1e20}}'
rc_ "unknown field" "colour" '{"scene":"fluid","colour":1,"fluid":{"size":[8,4,4],"viscosity":0.02},"run":{"steps":1}}'
rc_ "phi 0.9" "phi" '{"scene":"suspension","fidelity":"draft","phi":0.9,"Re_inf":12,"du_over_Uinf":0}'
rc_ "phi -0.1" "phi" '{"scene":"suspension","fidelity":"draft","phi":-0.1,"Re_inf":12,"du_over_Uinf":0}'
rc_ "fidelity bogus" "fidelity" '{"scene":"suspension","fidelity":"best","phi":0.1,"Re_inf":12,"du_over_Uinf":0}'
rc_ "du negative" "du_over_Uinf" '{"scene":"suspension","fidelity":"draft","phi":0.1,"Re_inf":12,"du_over_Uinf":-1}'
rc_ "device bogus" "device" '{"scene":"fluid","device":"tpu","fluid":{"size":[8,4,4],"viscosity":0.02},"run":{"steps":1}}'
rc_ "threads -2" "threads" '{"scene":"fluid","fluid":{"size":[8,4,4],"viscosity":0.02},"run":{"steps":1,"threads":-2}}'
rc_ "duplicate key" "scene|duplicate" '{"scene":"fluid","scene":"granular"}'
probe $fam "case missing" 2 "nope.json" -- "$F" run "$W/nope.json" --out "$W/rcx"
probe $fam "case a folder" 2 "" -- "$F" run "$W" --out "$W/rcy"
probe $fam "--out is a file" nz "precious" -- "$F" run "$U/tiny.json" --out "$U/precious.txt" --quiet
probe $fam "--out empty" nz "out" -- "$F" run "$U/tiny.json" --out "" --quiet
probe $fam "--stop-after x" 2 "stop-after" -- "$F" run "$U/tiny.json" --out "$W/sa" --stop-after x
probe $fam "--device tpu" 2 "device" -- "$F" run "$U/tiny.json" --out "$W/sa2" --device tpu
probe $fam "--device cuda without a GPU" any "" -- "$F" run "$U/tiny.json" --out "$W/sa3" --device cuda --quiet
probe $fam "tiny case runs" 0 "" -- "$F" run "$U/tiny.json" --out "$W/ok1" --quiet
probe $fam "same folder, another case" nz "result.json|another|case" -- "$F" run "$U/tiny04.json" --out "$W/ok1" --quiet
probe $fam "same case again" any "" -- "$F" run "$U/tiny.json" --out "$W/ok1" --quiet

# ====================================================== sweep options
fam=options
probe $fam "--lease nan" 2 "lease" -- "$F" sweep status --db "$W/done.db" --lease nan
probe $fam "--lease 1" 2 "lease" -- "$F" sweep status --db "$W/done.db" --lease 1
probe $fam "--grace -1" 2 "grace" -- "$F" sweep resume --db "$W/done.db" --grace -1 --worker "$FAKE"
probe $fam "--watch 0" 2 "watch" -- "$F" sweep status --db "$W/done.db" --watch 0
probe $fam "--watch 1 ends when idle" 0 "nothing is running" -- "$F" sweep status --db "$W/done.db" --watch 1
probe $fam "--backend pbs" 2 "backend" -- "$F" sweep launch "$U/fake.json" --db "$W/op.db" --backend pbs
probe $fam "--device tpu" 2 "device" -- "$F" sweep launch "$U/fake.json" --db "$W/op2.db" --device tpu
probe $fam "--device cuda (sweep)" nz "cuda" -- "$F" sweep launch "$U/real.json" --db "$W/op3.db" --device cuda
probe $fam "resume, several sweeps, no --sweep" any "" -- sh -c "'$F' sweep launch '$U/fails.json' --db '$W/two.db' --worker '$FAKE' >/dev/null 2>&1; '$F' sweep launch '$U/fake.json' --db '$W/two.db' --worker '$FAKE' >/dev/null 2>&1; exec '$F' sweep resume --db '$W/two.db' --worker '$FAKE'"
probe $fam "resume --sweep unknown" 2 "nope" -- "$F" sweep resume --db "$W/done.db" --sweep nope --worker "$FAKE"
probe $fam "resume with nothing to do" 0 "" -- "$F" sweep resume --db "$W/done.db" --worker "$FAKE"
probe $fam "launch again (all complete)" 0 "" -- "$F" sweep launch "$U/fake.json" --db "$W/done.db" --worker "$FAKE"
fake_sweep '"f"' "" '1,2,3' >"$W/grown.json"
probe $fam "a changed grid under the same name" any "" -- "$F" sweep launch "$W/grown.json" --db "$W/done.db" --worker "$FAKE"
printf '{"name":"f","base":{"x":0,"fake":{"steps":3}},"axes":{"x":[1,2]}}' >"$W/changed.json"
probe $fam "a changed base under the same name" any "" -- "$F" sweep launch "$W/changed.json" --db "$W/done.db" --worker "$FAKE"
probe $fam "no subcommand" 2 "" -- "$F"
probe $fam "sweep without action" 2 "" -- "$F" sweep
probe $fam "--version" 0 "[0-9]" -- "$F" --version
probe $fam "unknown option" 2 "bogus" -- "$F" query --db "$W/done.db" --bogus
probe $fam "sigterm during a sweep" any "" -- sh -c "'$F' sweep launch '$U/fake.json' --db '$W/sig.db' --worker '$FAKE' & p=\$!; sleep 0.5; kill -TERM \$p; wait \$p; exit 0"

# =================================================================== summary
echo
printf '%-16s %5s %5s %5s\n' family total good bad
tg=0 tb=0
for f in "${families[@]}"; do
  g=${fam_good[$f]} b=${fam_bad[$f]}
  tg=$((tg + g)) tb=$((tb + b))
  printf '%-16s %5s %5s %5s\n' "$f" $((g + b)) "$g" "$b"
done
printf '%-16s %5s %5s %5s\n' all $((tg + tb)) "$tg" "$tb"
if [ "$tb" -gt 0 ]; then
  echo
  echo "bad:"
  printf '  %s\n' "${bad_list[@]}"
  exit 1
fi
exit 0
