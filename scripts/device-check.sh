#!/usr/bin/env bash
# The device check: on a machine with a GPU, runs the GPU tests (lattice,
# immersed boundary, partially saturated cells and the samples' liquid
# averages), the GPU fluid benchmark (with the device's copy bandwidth measured
# in the same run), the GPU coupled-step benchmark (each coupling on the
# paper's case against the fluid alone), the CPU fluid benchmark on that
# machine's cores for the speed-up, and the fluid scene and the paper's case at
# the paper's box size on the GPU and on the CPU, writing every figure into one
# folder. Sized to finish in under 8 minutes when its tests pass (9-10 with the
# reruns below, which only failures start), so a 15-minute device session
# holds a passing check and the runs mode, or a failing check and its reruns.
#
# Time limits per step: 50 + 55 + 70 + 70 + 40 + 4 x 25 + 2 x 35 = 455 s at
# most, each with 5 s more for a step that ignores SIGTERM (a hung kernel):
# 510 s; between the steps the script's own work (the machine record, the
# library check, a tar of the logs after each step) takes about 15 s more:
# 525 s, inside the device tool's 600 s for one command. Where GPU tests fail,
# up to 2 x 20 s more rerun them with every launch waited for (below): 510 s,
# 575 s at the worst, still inside the 600 s, and a check that needs those has
# already said what it must.
# Usage (from the repository root, on the GPU machine):
#   scripts/device-check.sh [BUNDLE] [OUT] [check|runs]
#     BUNDLE: what scripts/device-bundle.sh packed here (default build/device-bundle)
#     OUT:    where the figures go (default $OUT, else device-check-out)
#     check (default): the steps below. runs: after a check that passed, whole
#       runs on the GPU for the device's remaining minutes instead (the
#       section "The runs" below; DEVICE_RUNS_LIMIT_S, default 240 s, at most 420)
# The device tool brings back at most 8 files of 16 MiB from OUT, so every log,
# result and benchmark file is written to a scratch folder beside the bundle and
# OUT gets three: summary.txt and machine.txt (kept current as steps run) and
# device-check.tgz (the scratch folder without checkpoints), repacked after
# each step.
# Exit 0 when every step ran and every GPU test passed; 1 otherwise (each
# step's log says which); 2 when the bundle is missing.
set -uo pipefail
cd "$(dirname "$0")/.." || exit 2
root=$(pwd)
out=${2:-${OUT:-device-check-out}}
mkdir -p "$out"
out=$(realpath "$out")
bundle=${1:-build/device-bundle}
what=${3:-check}
if [[ $what != check && $what != runs ]]; then
  echo "device-check: third argument '$what': must be check or runs" | tee "$out/summary.txt"
  exit 2
fi
if [[ ! -x $bundle/bin/flocsim ]]; then
  echo "device-check: no bundle at $bundle (bin/flocsim missing): pack one with" \
       "scripts/device-bundle.sh here and carry it" | tee "$out/summary.txt"
  exit 2
fi
bundle=$(realpath "$bundle")
work="$root/device-check-work"  # everything but the summary; tarred into $out at the end
rm -rf "$work"
mkdir -p "$work"
host_library_path=${LD_LIBRARY_PATH:-}  # where the machine keeps its libraries (the CUDA driver's)
started=$(date +%s)

# what the machine is, before anything can fail: enough to diagnose a failure
# from OUT alone (with the machine's own libraries: the bundle's come after).
# The bundle's CUDA 13 runtime needs driver 580 or newer; an older one makes
# the first GPU step exit 77 with that reason, and the check stop there.
# Without persistence mode each CUDA process start pays the driver's
# initialisation (seconds).
{
  date -u
  nvidia-smi --query-gpu=name,memory.total,clocks.max.memory,driver_version,compute_mode,persistence_mode --format=csv
  nvidia-smi
  nproc
  lscpu | grep -i "model name"
  grep -m1 "^flags" /proc/cpuinfo
  ldd --version | head -n 1
  grep -E "^(PRETTY_NAME|VERSION)=" /etc/os-release
  nvcc --version | tail -n 2
  echo "bundle: $(cat "$bundle/build.txt" 2> /dev/null)"
} > "$out/machine.txt" 2>&1
cat "$out/machine.txt"

# Without persistence mode the driver lets the GPU go whenever no process
# holds it, and each of the check's CUDA processes pays its initialisation
# again (seconds, against step limits of 25-35 s). A monitor holds it for the
# whole script (NVML is no compute context, so an exclusive compute mode is
# unaffected) and logs the GPU's load and clocks beside the steps.
nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used,clocks.sm,clocks.mem,temperature.gpu,power.draw \
  --format=csv -l 5 > "$work/nvidia-smi-monitor.csv" 2>&1 &
monitor=$!
trap 'kill $monitor 2> /dev/null' EXIT

export LD_LIBRARY_PATH="$bundle/lib${host_library_path:+:$host_library_path}"
export FLOCSIM_EXE="$bundle/bin/flocsim" FLOCSIM_SOURCE_DIR="$root"
export OMP_WAIT_POLICY=passive  # the GPU steps' host threads mostly wait; CPU steps unset it
status=0
last_rc=0  # the exit code of the step that ran last
ok_codes="0"  # the exit codes a step may end with

pack() {  # the scratch folder into OUT, without checkpoints (each about 1 GB)
  # checkpoints (*.h5) and any half-written one (.NAME.tmp.*, left by a step
  # killed while it wrote) stay out: each is about 1 GB
  tar czf "$out/device-check.tgz" --exclude='*.h5' --exclude='.*.tmp.*' -C "$work" . 2> /dev/null
  ls -la "$out"
}

# The bundle is x86-64 code: on another architecture (a Grace Hopper's
# aarch64, say) nothing of it can start, whatever the flags below say.
if [[ $(uname -m) != x86_64 ]]; then
  echo "device-check: this machine is $(uname -m); the bundle is x86-64 code. Build the" \
       "device preset on (or for) $(uname -m) and pack that build" | tee -a "$out/summary.txt"
  exit 1
fi

# Binaries built for vector instructions this processor lacks stop with
# "Illegal instruction": say so first (device-bundle.sh lists what the build
# assumed; the default device build assumes x86-64-v3, AVX2).
if [[ -f $bundle/cpu-flags.txt ]]; then
  for flag in $(cat "$bundle/cpu-flags.txt"); do
    if ! grep -q -w "$flag" /proc/cpuinfo; then
      echo "device-check: this processor lacks $flag, which the bundle was built for; build" \
           "the device preset with a lower -march and pack that build" | tee -a "$out/summary.txt"
      exit 1
    fi
  done
fi

# Every shared library the programs need must resolve from the bundle or the
# machine. Where the machine's C library is older than the one the bundle was
# built against ("version `GLIBC_2.36' not found"), each program starts
# through the bundle's own loader and C library (lib/glibc) instead: wrappers
# in the scratch folder, which FLOCSIM_EXE names too, so the tests' child runs
# take the same way. The machine's own tools keep the machine's C library.
# DEVICE_CHECK_BUNDLED_LIBC=1 takes that way on any machine (to try it here).
bin="$bundle/bin"
ldd "$bundle"/bin/* > "$work/ldd.txt" 2>&1
if grep -q "version .GLIBC_[0-9.]*. not found" "$work/ldd.txt" || [[ ${DEVICE_CHECK_BUNDLED_LIBC:-} == 1 ]]; then
  loader=$(ls "$bundle"/lib/glibc/ld-linux* 2> /dev/null | head -n 1)
  why="older than the bundle's ($(cat "$bundle/lib/glibc/version.txt" 2> /dev/null))"
  [[ ${DEVICE_CHECK_BUNDLED_LIBC:-} == 1 ]] && why="set aside (DEVICE_CHECK_BUNDLED_LIBC=1)"
  echo "device-check: the machine's C library ($(ldd --version 2>&1 | head -n 1)) is $why:" \
       "the programs start through the bundled loader" \
       "${loader:-(missing: repack with scripts/device-bundle.sh)}" | tee -a "$out/summary.txt"
  libpath="$bundle/lib/glibc:$bundle/lib${host_library_path:+:$host_library_path}"
  mkdir -p "$work/bin"
  for p in "$bundle"/bin/*; do
    printf '#!/bin/bash\nexec %q --library-path %q %q "$@"\n' "$loader" "$libpath" "$p" \
      > "$work/bin/$(basename "$p")"
    chmod +x "$work/bin/$(basename "$p")"
  done
  bin="$work/bin"
  # the tests' child runs; a sweep's workers would need FLOCSIM_WORKER too
  # (through the loader, /proc/self/exe names the loader)
  export FLOCSIM_EXE="$bin/flocsim" FLOCSIM_WORKER="$bin/flocsim"
  # the machine's own tools (nvidia-smi, nvcc, tar) keep the machine's
  # libraries: the bundle's want the newer C library
  export LD_LIBRARY_PATH="$host_library_path"
  [[ -z $LD_LIBRARY_PATH ]] && unset LD_LIBRARY_PATH
  # the programs, and the machine's CUDA driver as they will load it (its
  # dependencies must resolve to the bundled C library's family)
  libcuda=$(ldconfig -p 2> /dev/null | awk '/libcuda\.so\.1 / {print $NF; exit}')
  for p in "$bundle"/bin/* $libcuda; do
    echo "$p:"
    "$loader" --library-path "$libpath" --list "$p"
  done > "$work/ldd.txt" 2>&1
fi
if grep -E "not found" "$work/ldd.txt" | tee -a "$out/summary.txt" | grep -q .; then
  echo "device-check: unresolved libraries above (ldd.txt in device-check.tgz)" |
    tee -a "$out/summary.txt"
  pack
  exit 1
fi

kill_after=5  # seconds a step may take to end after its limit's SIGTERM
step() {  # step NAME TIMEOUT_S COMMAND...: runs it, logs it, records its exit code
  local name=$1 limit=$2
  shift 2
  echo "== $name ($(($(date +%s) - started)) s in)" | tee -a "$out/summary.txt"
  # line-buffered, so a step killed at its limit leaves what it printed; -k:
  # a step stuck in a kernel ignores SIGTERM (it is checked between steps)
  timeout -k "$kill_after" "$limit" stdbuf -oL -eL "$@" > "$work/$name.log" 2>&1
  local rc=$?
  echo "   exit $rc" | tee -a "$out/summary.txt"
  tail -n 25 "$work/$name.log"
  [[ " $ok_codes " == *" $rc "* ]] || status=1
  last_rc=$rc
  # what has run so far, into OUT now: should the device tool stop the
  # script at its limit, the logs up to there still come back
  pack > /dev/null
}


# The runs: once a check has passed, the device's remaining minutes go to
# whole runs on the GPU, in two groups, one after the other; the sweeps of a
# group are launched at once (their workers share the GPU; two OpenMP threads
# each for the sphere side on the machine's cores), each into its own
# database in the scratch folder:
# 1. gpu-precision-a4 (4 workers): the phi 0.20, Re_inf 12 comparison point
#    and its baseline at a = 4 in float and double, the back-end's own figure
#    (the float-against-double trade; its float runs repeat the CPU's
#    committed ones, same seed), first because its runs are the shorter;
# 2. corners-paper (4) and corners-extra-paper (1): the paper preset's
#    accepted corners (the refused ones are recorded as refused).
# On a GPU in an exclusive compute mode (one process at a time) each sweep
# runs alone with one worker. DEVICE_RUNS_DEVICE=cpu runs them on the CPU
# instead (to try the mode here).
# What is not done by DEVICE_RUNS_LIMIT_S stops with its checkpoint:
# timeout's SIGTERM reaches the whole process group, each orchestrator has its
# workers checkpoint (--grace 45: it kills and records a straggler itself),
# and the launching shell, which notes the signal and starts no further
# group, waits for the orchestrators up to 60 s (a paper-size checkpoint in
# double is about 1 GB) before timeout kills what is left. Worst case: the
# limit + 60 + 3 x 25 s for the statuses + a few seconds of packing and the
# machine record; hence the limit's ceiling of 420 s, inside the device
# tool's 600 s for one command.
if [[ $what == runs ]]; then
  limit=${DEVICE_RUNS_LIMIT_S:-240}
  if ! [[ $limit =~ ^[0-9]+$ ]] || ((limit < 1 || limit > 420)); then
    echo "device-check: DEVICE_RUNS_LIMIT_S = '$limit': must be a whole number of seconds" \
         "from 1 to 420 (the device tool's 600 s per command less what the mode adds)" |
      tee -a "$out/summary.txt"
    exit 2
  fi
  groups=("gpu-precision-a4:4" "corners-paper:4 corners-extra-paper:1")
  if nvidia-smi --query-gpu=compute_mode --format=csv,noheader 2> /dev/null | grep -qi exclusive; then
    echo "device-check: the GPU is in an exclusive compute mode (one process at a time):" \
         "each sweep runs alone with one worker" | tee -a "$out/summary.txt"
    groups=("gpu-precision-a4:1" "corners-paper:1" "corners-extra-paper:1")
  fi
  export OMP_NUM_THREADS=2
  # a named worker skips the launch's plan, which would time every
  # configuration on this machine's CPU before the first worker starts
  export FLOCSIM_WORKER="$bin/flocsim"
  kill_after=60
  ok_codes="0 124"  # 124: the limit came first; what ran stopped with its checkpoints
  step gpu-runs "$limit" bash -c '
    flocsim=$1 work=$2 device=$3
    shift 3
    stopping=""
    trap "stopping=1" TERM  # a trap, not an ignore: the launches keep the default
    finished() {  # finished PID: its exit code, waiting on through a SIGTERM
      local code
      while :; do
        wait "$1"
        code=$?
        kill -0 "$1" 2> /dev/null || return $code
      done
    }
    rc=0  # 1 when a launch was refused (2) or ended in another unexpected way
    for group in "$@"; do
      [[ -n $stopping ]] && break
      pids=() names=()
      for sweep_jobs in $group; do
        sweep=${sweep_jobs%:*}
        "$flocsim" sweep launch "sweeps/$sweep.json" --db "$work/$sweep.sqlite" \
          --runs-dir "$work/runs-$sweep" --jobs "${sweep_jobs#*:}" --device "$device" \
          --grace 45 > "$work/launch-$sweep.log" 2>&1 &
        pids+=($!) names+=("$sweep")
      done
      for i in "${!pids[@]}"; do
        finished "${pids[$i]}"
        code=$?
        # 0: all completed; 1: some failed or were refused; 3: stopped at the limit
        echo "${names[$i]}: sweep launch exit $code"
        ((code == 0 || code == 1 || code == 3)) || rc=1
      done
    done
    exit $rc' _ "$bin/flocsim" "$work" "${DEVICE_RUNS_DEVICE:-cuda}" "${groups[@]}"
  grep "sweep launch exit" "$work/gpu-runs.log" | tee -a "$out/summary.txt"
  ok_codes="0"
  kill_after=5
  for sweep in gpu-precision-a4 corners-paper corners-extra-paper; do
    [[ -f $work/launch-$sweep.log ]] || continue  # its group never started
    { echo "   launch $sweep, its last lines:"; tail -n 5 "$work/launch-$sweep.log"; } |
      tee -a "$out/summary.txt"
    step "status-$sweep" 20 "$bin/flocsim" sweep status --db "$work/$sweep.sqlite"
    cat "$work/status-$sweep.log" >> "$out/summary.txt"
  done
  echo "== runs done in $(($(date +%s) - started)) s, status $status" | tee -a "$out/summary.txt"
  pack
  exit $status
fi

# A kernel that faults is reported by whichever later call waits for the GPU,
# and it leaves the process's context unusable, so every later test of that
# program fails too: one fault reads as dozens. Where a test program failed,
# rerun_blocking reruns its failed tests (or, where it died mid-test, the test
# it was in) with CUDA_LAUNCH_BLOCKING=1, every launch waited for, so that
# the error names its own launch. Only then: the first run keeps the
# asynchronous path (the lattice step overlapping the sphere side) under test.
rerun_blocking() {  # rerun_blocking NAME PROGRAM, after step NAME ran PROGRAM
  local name=$1 program=$2 tests
  ((last_rc == 0 || last_rc == 77)) && return
  [[ -f $work/$name.log ]] || return
  # the first failures in the order they failed (the first is the one that
  # counts: a fault fails everything after it), at most four, and the test
  # the program died in, if it died within one
  tests=$(awk '$1 == "[" && $3 == "]" && $4 ~ /\./ {
      name = $4; sub(/,$/, "", name)
      if ($2 == "RUN") running = name
      else if ($2 == "OK") running = ""
      else if ($2 == "FAILED") { running = ""; if (!seen[name]++ && n < 4) failed[n++] = name }
    }
    END { for (i = 0; i < n; ++i) print failed[i]; if (running != "" && !seen[running]) print running }' \
    "$work/$name.log" | paste -sd: -)
  [[ -z $tests ]] && return
  step "$name-blocking" 20 env CUDA_LAUNCH_BLOCKING=1 "$program" --gtest_filter="$tests"
}

# 1. the GPU against the CPU reference (tests/lattice_gpu; tests/coupling_gpu:
#    the immersed boundary and the liquid averages, a 200-step suspension run
#    on each device among them)
step gpu-tests 50 "$bin/test_gpu_lattice" --gtest_output="json:$work/gpu-tests.json"
# 77: no usable GPU (no driver, one too old for CUDA 13, none visible): every
# later GPU step would say the same, so stop here with the reason
if ((last_rc == 77)); then
  grep -m 1 "no GPU" "$work/gpu-tests.log" | tee -a "$out/summary.txt"
  echo "device-check: no usable GPU (above); stopped before the other steps" |
    tee -a "$out/summary.txt"
  pack
  exit 1
fi
rerun_blocking gpu-tests "$bin/test_gpu_lattice"
step gpu-coupling-tests 55 "$bin/test_gpu_coupling" \
  --gtest_output="json:$work/gpu-coupling-tests.json"
rerun_blocking gpu-coupling-tests "$bin/test_gpu_coupling"

# 2. the fluid kernel: paper's box and 256^3, float and double, against the
#    device's copy bandwidth
step bench-fluid-gpu 70 "$bin/bench_fluid_gpu" --reps 5 --steps 100 \
  --json "$work/bench-fluid-gpu.json"

# 2b. the coupled step on the paper's case (a = 6, N = 1320): the immersed
#     boundary's presets' schemes, float and double, against the fluid alone
step bench-coupling-gpu 70 "$bin/bench_coupling_gpu" --reps 5 --steps 20 \
  --json "$work/bench-coupling-gpu.json"

# 3. the CPU kernel on this machine's cores at 256^3, the GPU's second box,
#    for the speed-up
# (the CPU figures with OpenMP's default waiting: passive threads, which suit
# a process that mostly waits for the GPU, would understate the CPU's rate)
step bench-fluid-cpu 40 env -u OMP_WAIT_POLICY "$bin/bench_fluid" --threads "$(nproc)" --reps 3 --steps 10 \
  --size 256 --precision all --forcing uniform --json "$work/bench-fluid-cpu.json"

# 4. the fluid scene at the paper's box (288 x 144 x 144): a shear wave with
#    a body force, float and double, on the GPU; and on the CPU for the ratio
for precision in float double; do
  for device in cuda cpu; do
    steps=4000 cpu_env=()
    [[ $device == cpu ]] && steps=100 cpu_env=(env -u OMP_WAIT_POLICY)
    cat > "$work/paper-box-$precision-$device.json" <<CASE
{"scene": "fluid", "precision": "$precision", "device": "$device",
 "fluid": {"size": [288, 144, 144], "viscosity": 0.01, "body_force": [1e-7, 0, 0],
           "initial": {"type": "shear_wave", "amplitude": 0.02, "axis": "x", "component": "y"}},
 "run": {"steps": $steps, "progress_every_s": 10, "threads": 0}}
CASE
    step "run-paper-box-$precision-$device" 25 ${cpu_env[@]+"${cpu_env[@]}"} "$bin/flocsim" run \
      "$work/paper-box-$precision-$device.json" --out "$work/run-paper-box-$precision-$device" --quiet
  done
done

# 5. the paper's case (phi 0.2, Re_inf 12, du 0.025, the paper preset: a = 6,
#    288 x 144 x 144, N = 1320) on the GPU for 1500 steps (5 a/U_inf), and
#    on the CPU for 30, stopped as if by SIGTERM (exit 3, a checkpoint): their
#    logs give the full step's rate on each, run.log the modules' split
cat > "$work/paper-case.json" <<CASE
{"scene": "suspension", "fidelity": "paper", "phi": 0.2, "Re_inf": 12, "du_over_Uinf": 0.025,
 "density_ratio": 4.0, "delta_over_a": 0.025, "protocol": {"progress_every_s": 5}}
CASE
for device in cuda cpu; do
  steps=1500 cpu_env=()
  [[ $device == cpu ]] && steps=30 cpu_env=(env -u OMP_WAIT_POLICY)
  ok_codes="0 3"  # a stop on request exits 3: that is this step's success
  step "run-paper-case-$device" 35 ${cpu_env[@]+"${cpu_env[@]}"} "$bin/flocsim" run "$work/paper-case.json" \
    --out "$work/run-paper-case-$device" --device "$device" --stop-after "$steps" --quiet
  ok_codes="0"
done

echo "== done in $(($(date +%s) - started)) s, status $status" | tee -a "$out/summary.txt"
pack
exit $status
