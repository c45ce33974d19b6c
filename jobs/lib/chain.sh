# shellcheck shell=bash
# The logic shared by the job scripts in jobs/slurm and jobs/pbs: environment
# activation, the wall-time restart chain, job-array cases and the dependent
# post-processing job.  Sourced by the scripts, never run by itself.
#
# A job script sets MPIPD_SCHED (slurm | pbs) and its settings (MPIPD_*, see
# jobs/README.md), sources this file and calls one of
#   mpipd_job_run          one run: MPIPD_SCENE -> MPIPD_OUT
#   mpipd_job_sweep        one case of a job array: MPIPD_OUT/<case>
#   mpipd_job_postprocess  python -m mpipd.post on finished run folder(s)
#
# One link of a chain:
#   1. a deadline for the job's own timer: the wall-time limit the scheduler
#      reports, minus MPIPD_WALLTIME_MARGIN (a backstop for SLURM's
#      --signal=B:USR1@..., the only mechanism on PBS, which sends no warning);
#   2. `mpipd run SCENE` on the first link, `mpipd run --restart OUT/checkpoint.h5`
#      on the next ones, started in the background under MPIPD_LAUNCHER;
#   3. USR1 or TERM to the batch shell, or the timer, is forwarded to the launcher
#      as USR1 (mpirun and srun pass USR1 on to every rank); mpipd then writes
#      OUT/checkpoint.h5 and exits.  The forward waits until mpipd is stepping
#      (a progress line in OUT/run.log, or MPIPD_SIGNAL_GRACE seconds), because a
#      USR1 that reaches a rank before mpipd has installed its handler kills it;
#   4. the run's state decides: finished -> exit 0 (and submit the post-processing
#      job if MPIPD_SUBMIT_POSTPROCESS=1); checkpointed further than the link
#      started -> continue the chain (SLURM: requeue this job, same job id;
#      PBS: submit this script again); anything else -> stop with an error.
# Every event is appended to OUT/chain.log.

# defaults of the settings a job script may leave out
: "${MPIPD_MAX_LINKS:=20}" "${MPIPD_SIGNAL_GRACE:=120}" "${MPIPD_WALLTIME_MARGIN:=300}"
: "${MPIPD_CHECK:=1}" "${MPIPD_SUBMIT_POSTPROCESS:=0}" "${MPIPD_POSTPROCESS:=report}"

# A stop request (USR1/TERM) can come before mpipd runs, e.g. from SLURM's
# --signal, which may fire up to a minute early: note it from the first line on
# (the default action would kill the batch shell) and act on it once mpipd runs.
_CHAIN_REQ=""
trap '_CHAIN_REQ=${_CHAIN_REQ:-"USR1 from the scheduler"}' USR1
trap '_CHAIN_REQ=${_CHAIN_REQ:-"TERM from the scheduler"}' TERM

# ---------------------------------------------------------------- helpers

_chain_die() { echo "mpipd-job: error: $*" >&2; exit "${2:-1}"; }

_chain_now() { date +%s; }

# seconds from [D-]HH:MM:SS, MM:SS or SS; empty for UNLIMITED / unknown
_chain_seconds() {
  local s=$1 d=0 h=0 m=0 x
  case "$s" in ''|UNLIMITED|NOT_SET|INVALID|N/A|*[!0-9:-]*) return 0 ;; esac
  if [[ $s == *-* ]]; then d=${s%%-*}; s=${s#*-}; fi
  IFS=: read -r -a x <<<"$s"
  case ${#x[@]} in
    3) h=${x[0]}; m=${x[1]}; s=${x[2]} ;;
    2) m=${x[0]}; s=${x[1]} ;;
    1) s=${x[0]} ;;
    *) return 0 ;;
  esac
  echo $(( ((10#$d * 24 + 10#$h) * 60 + 10#$m) * 60 + 10#$s ))
}

# the job id, the array index and the rank count, per scheduler
_chain_job_id() {
  case $MPIPD_SCHED in
    slurm) local s; s=$(_chain_slurm_self); echo "${s:-none}" ;;
    pbs) echo "${PBS_JOBID:-none}" ;;
  esac
}

# this job for scontrol/squeue/dependencies: an array task as JOBID_TASK, because
# SLURM gives one task the array's own id, and that id means the whole array
_chain_slurm_self() {
  if [ -n "${SLURM_ARRAY_JOB_ID:-}" ] && [ -n "${SLURM_ARRAY_TASK_ID:-}" ]; then
    echo "${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}"
  else
    echo "${SLURM_JOB_ID:-}"
  fi
}

_chain_array_index() {
  if [ -n "${MPIPD_CASE_INDEX:-}" ]; then echo "$MPIPD_CASE_INDEX"; return; fi
  case $MPIPD_SCHED in
    slurm) echo "${SLURM_ARRAY_TASK_ID:-}" ;;
    pbs) echo "${PBS_ARRAY_INDEX:-${PBS_ARRAYID:-}}" ;;
  esac
}

_chain_ntasks() {
  if [ -n "${MPIPD_NTASKS:-}" ]; then echo "$MPIPD_NTASKS"; return; fi
  case $MPIPD_SCHED in
    slurm) echo "${SLURM_NTASKS:-1}" ;;
    pbs) if [ -n "${PBS_NODEFILE:-}" ] && [ -r "$PBS_NODEFILE" ]; then wc -l <"$PBS_NODEFILE" | tr -d ' '
         else echo "${PBS_NP:-1}"; fi ;;
  esac
}

# seconds left before the scheduler's wall-time limit (empty: unknown / unlimited)
_chain_time_left() {
  case $MPIPD_SCHED in
    slurm)
      [ -n "${SLURM_JOB_ID:-}" ] || return 0
      _chain_seconds "$(squeue -h -j "$(_chain_slurm_self)" -o %L 2>/dev/null | head -1)" ;;
    pbs)
      [ -n "${PBS_JOBID:-}" ] || return 0
      local q lim used
      q=$(qstat -f "$PBS_JOBID" 2>/dev/null)
      lim=$(sed -n 's/^ *Resource_List.walltime = //p' <<<"$q" | head -1)
      used=$(sed -n 's/^ *resources_used.walltime = //p' <<<"$q" | head -1)
      lim=$(_chain_seconds "${lim:-}")
      if [ -z "$lim" ] && [ -n "${PBS_WALLTIME:-}" ]; then lim=$PBS_WALLTIME; fi   # Torque
      [ -n "$lim" ] || return 0
      used=$(_chain_seconds "${used:-0}")
      echo $(( lim - ${used:-0} )) ;;
  esac
}

# the environment: modules, then the virtualenv, then OpenMP off
mpipd_activate() {
  if [ -n "${MPIPD_MODULES:-}" ]; then
    # shellcheck disable=SC1091
    command -v module >/dev/null 2>&1 || [ -z "${MODULESHOME:-}" ] || . "$MODULESHOME/init/bash"
    # shellcheck disable=SC2086
    module load $MPIPD_MODULES || _chain_die "module load $MPIPD_MODULES failed"
  fi
  local venv=${MPIPD_VENV:-$MPIPD_ROOT/.venv}
  if [ "$venv" != none ]; then
    [ -f "$venv/bin/activate" ] || _chain_die "no virtualenv at $venv (run 'make install' in $MPIPD_ROOT, or set MPIPD_VENV=none and MPIPD_MODULES)"
    # shellcheck disable=SC1091
    . "$venv/bin/activate"
  fi
  export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
  export HDF5_USE_FILE_LOCKING=${HDF5_USE_FILE_LOCKING:-FALSE}
  command -v mpipd >/dev/null || _chain_die "mpipd is not on PATH after activation"
}

# the common start of every job: timer deadline, project root, environment
mpipd_job_start() {
  _CHAIN_T0=$(_chain_now)
  local left
  left=$(_chain_time_left)
  _CHAIN_DEADLINE=""
  if [ -n "$left" ] && [ "${MPIPD_WALLTIME_MARGIN:-0}" -gt 0 ]; then
    if (( left > MPIPD_WALLTIME_MARGIN )); then
      _CHAIN_DEADLINE=$(( _CHAIN_T0 + left - MPIPD_WALLTIME_MARGIN ))
    else
      echo "mpipd-job: warning: wall time left (${left}s) <= MPIPD_WALLTIME_MARGIN" \
           "(${MPIPD_WALLTIME_MARGIN}s): own timer off" >&2
    fi
  fi
  _CHAIN_LEFT=${left:-unlimited}
  cd "$MPIPD_ROOT" || _chain_die "MPIPD_ROOT=$MPIPD_ROOT is not a folder"
  mpipd_activate
  MPIPD_LAUNCHER=${MPIPD_LAUNCHER:-$(_chain_default_launcher)}
}

_chain_default_launcher() {
  case $MPIPD_SCHED in
    slurm) echo "srun --mpi=pmix" ;;
    pbs) echo "mpirun -n $(_chain_ntasks)" ;;
  esac
}

_chain_log() {   # message -> stdout and OUT/chain.log
  local line
  line="$(date +%FT%T) job $(_chain_job_id) chain $_CHAIN_ID link $_CHAIN_LINK: $*"
  echo "mpipd-job: $line"
  echo "$line" >>"$_CHAIN_OUT/chain.log"
}

_chain_state() {   # -> "STATE STEP STEPS"
  python "$MPIPD_ROOT/jobs/lib/runstate.py" "$1" 2>/dev/null || echo "none 0 0"
}

# ---------------------------------------------------------------- one link

# mpipd_chain_run OUT SCENE [mpipd run args...]
mpipd_chain_run() {
  _CHAIN_OUT=$1; local scene=$2; shift 2
  local first_args=("$@")
  mkdir -p "$_CHAIN_OUT" || _chain_die "cannot create $_CHAIN_OUT"
  _CHAIN_ID=${MPIPD_CHAIN_ID:-$(_chain_job_id)}
  local started=0
  [ -f "$_CHAIN_OUT/chain.log" ] && started=$(grep -c ' link [0-9]*: start ' "$_CHAIN_OUT/chain.log")
  _CHAIN_LINK=$(( started + 1 ))
  local st step0 steps
  read -r st step0 steps <<<"$(_chain_state "$_CHAIN_OUT")"
  if [ "$st" = "done" ]; then
    _CHAIN_LINK=$(( _CHAIN_LINK - 1 ))
    _chain_log "already finished ($steps steps in $_CHAIN_OUT/run.h5): nothing to do"
    _chain_finished
    return 0
  fi
  if (( _CHAIN_LINK > MPIPD_MAX_LINKS )); then
    _chain_log "stop: $MPIPD_MAX_LINKS links already (MPIPD_MAX_LINKS); the run is at step $step0 of $steps"
    exit 1
  fi
  local ntasks cmd=()
  ntasks=$(_chain_ntasks)
  if [ "$st" = partial ]; then
    cmd=(mpipd run --restart "$_CHAIN_OUT/checkpoint.h5")
    local a
    for a in "${first_args[@]}"; do          # flags only: the scene and --set are in the checkpoint
      case $a in --force|--quiet) cmd+=("$a") ;; esac
    done
  else
    cmd=(mpipd run "$scene" --out "$_CHAIN_OUT" "${first_args[@]}")
    if [ "$st" = started ] && grep -q " chain $_CHAIN_ID " "$_CHAIN_OUT/chain.log" 2>/dev/null; then
      cmd+=(--overwrite)      # this chain's own first link died before its first checkpoint
    fi
    if [ "${MPIPD_CHECK:-1}" = 1 ]; then
      local sets=() i=0
      while (( i < ${#first_args[@]} )); do
        case ${first_args[i]} in
          --set) sets+=(--set "${first_args[i+1]:-}"); i=$((i + 1)) ;;
          --set=*) sets+=("${first_args[i]}") ;;
        esac
        i=$((i + 1))
      done
      mpipd check "$scene" --ranks "$ntasks" "${sets[@]}" || _chain_die "mpipd check $scene failed" 2
    fi
  fi
  _chain_log "start on $(hostname -s), $ntasks rank(s), wall time left ${_CHAIN_LEFT}s, run at step $step0: $MPIPD_LAUNCHER ${cmd[*]}"
  local logsize=0
  [ -f "$_CHAIN_OUT/run.log" ] && logsize=$(wc -c <"$_CHAIN_OUT/run.log")

  local t_launch forwarded=0 held=0 pid rc ready
  t_launch=$(_chain_now)
  # shellcheck disable=SC2086
  $MPIPD_LAUNCHER "${cmd[@]}" &
  pid=$!
  while kill -0 "$pid" 2>/dev/null; do
    sleep 1 &
    wait $! 2>/dev/null
    if [ -z "$_CHAIN_REQ" ] && [ -n "$_CHAIN_DEADLINE" ] && (( $(_chain_now) >= _CHAIN_DEADLINE )); then
      _CHAIN_REQ="own timer (${MPIPD_WALLTIME_MARGIN}s before the wall-time limit)"
    fi
    if [ -n "$_CHAIN_REQ" ] && [ $forwarded = 0 ]; then
      ready=0
      if [ -f "$_CHAIN_OUT/run.log" ] && tail -c +$((logsize + 1)) "$_CHAIN_OUT/run.log" | grep -q '^step '; then
        ready=1
      elif (( $(_chain_now) - t_launch >= MPIPD_SIGNAL_GRACE )); then
        ready=1
      fi
      if [ $ready = 1 ]; then
        kill -USR1 "$pid" 2>/dev/null && forwarded=1
        _chain_log "checkpoint requested: $_CHAIN_REQ; USR1 forwarded to the launcher (pid $pid)"
      elif [ $held = 0 ]; then
        held=1
        _chain_log "checkpoint requested: $_CHAIN_REQ; held until mpipd is stepping"
      fi
    fi
  done
  wait "$pid"
  rc=$?
  local step1
  read -r st step1 steps <<<"$(_chain_state "$_CHAIN_OUT")"
  _chain_log "mpipd exited with status $rc after $(( $(_chain_now) - t_launch ))s; run $st at step $step1 of $steps"
  if [ "$st" = "done" ]; then
    _chain_finished
    return 0
  fi
  if [[ $_CHAIN_REQ == TERM* ]]; then
    # scancel, or the hard limit itself: never resurrect a cancelled job
    _chain_log "stop: TERM (scancel, or the wall-time limit was reached); the run is at step $step1; submit the job script again to continue"
    exit 143
  fi
  if (( rc == 2 || rc == 3 )); then
    _chain_log "stop: mpipd refused the input or the run became unstable (status $rc); see $_CHAIN_OUT/run.log"
    exit "$rc"
  fi
  if [ "$st" != partial ] || (( step1 <= step0 )); then
    _chain_log "stop: no progress in this link (a checkpoint at step $step1, the link started at $step0)"
    exit 1
  fi
  _chain_continue
}

# the run is finished: optionally submit the post-processing job
_chain_finished() {
  _chain_log "finished: $_CHAIN_OUT/run.h5"
  [ "${MPIPD_SUBMIT_POSTPROCESS:-0}" = 1 ] || return 0
  local out jid
  out=$(cd "$_CHAIN_OUT" && pwd)
  case $MPIPD_SCHED in
    slurm)
      # shellcheck disable=SC2086
      jid=$(cd "$MPIPD_ROOT" && _chain_clean_env sbatch --parsable --dependency="afterok:$(_chain_slurm_self)" \
              --export=ALL,MPIPD_RUN="$out" ${MPIPD_POSTPROCESS_SUBMIT_ARGS:-} \
              "$MPIPD_ROOT/jobs/slurm/postprocess.sbatch") ;;
    pbs)
      # no -W depend: the run is complete already, and PBS Pro takes no
      # dependency on an array subjob
      # shellcheck disable=SC2086
      jid=$(cd "$MPIPD_ROOT" && qsub -v "MPIPD_RUN=$out,MPIPD_ROOT=$MPIPD_ROOT" \
              ${MPIPD_POSTPROCESS_SUBMIT_ARGS:-} "$MPIPD_ROOT/jobs/pbs/postprocess.pbs") ;;
  esac
  if [ -n "$jid" ]; then _chain_log "submitted post-processing job $jid"
  else _chain_log "warning: could not submit the post-processing job"; fi
}

# nested sbatch must not inherit this job's SLURM_* settings
_chain_clean_env() {
  local unset=() v
  for v in $(compgen -v SLURM_); do [ "$v" = SLURM_CONF ] || unset+=(-u "$v"); done
  env "${unset[@]}" "$@"
}

# continue the chain: requeue (SLURM, same job id) or submit again
_chain_continue() {
  local how=${MPIPD_CHAIN:-requeue}
  if [ "$how" = none ]; then
    _chain_log "checkpointed; MPIPD_CHAIN=none: continue with the same job script (it restarts from the checkpoint)"
    exit 75
  fi
  if [ "$MPIPD_SCHED" = slurm ] && [ "$how" = requeue ]; then
    # SLURM stops this script as soon as the requeue is accepted, so log first
    _chain_log "requeueing job $(_chain_slurm_self) (scontrol requeue): the next link restarts from the checkpoint"
    if scontrol requeue "$(_chain_slurm_self)"; then
      sleep 60 & wait $!           # SLURM ends this run of the job here
      exit 0
    fi
    _chain_log "scontrol requeue failed (the site may forbid it): submitting a new job instead"
  fi
  local idx jid script
  idx=$(_chain_array_index)
  # the next link gets this link's settings through the environment (sbatch
  # --export=ALL, qsub -V), so the script needs no arguments
  export MPIPD_CHAIN_ID=$_CHAIN_ID MPIPD_CASE_INDEX=$idx
  export "${!MPIPD_@}"
  case $MPIPD_SCHED in
    slurm)
      # scontrol's Command= is the script path followed by its arguments
      local self
      self=$(_chain_slurm_self)
      script=${MPIPD_JOB_SCRIPT:-$(scontrol show job "$self" 2>/dev/null | sed -n 's/^ *Command=//p' | head -1)}
      script=${script%% *}
      [ -f "$script" ] || script=$MPIPD_ROOT/$script
      local opts=(--parsable --dependency="afterany:$self" --job-name="$SLURM_JOB_NAME"
                  --nodes="$SLURM_JOB_NUM_NODES" --ntasks="$SLURM_NTASKS" --open-mode=append
                  --time="$(squeue -h -j "$self" -o %l | head -1)")
      # an array task continues as a one-task array with its own index: the
      # script's --array line would otherwise start the whole sweep again
      [ -n "${SLURM_ARRAY_TASK_ID:-}" ] && opts+=(--array="$SLURM_ARRAY_TASK_ID")
      [ -n "${SLURM_JOB_PARTITION:-}" ] && opts+=(--partition="$SLURM_JOB_PARTITION")
      [ -n "${SLURM_JOB_ACCOUNT:-}" ] && opts+=(--account="$SLURM_JOB_ACCOUNT")
      local so
      so=$(scontrol show job "$self" 2>/dev/null | sed -n 's/^ *StdOut=//p' | head -1)
      [ -n "$so" ] && opts+=(--output="$so")
      jid=$(cd "$MPIPD_ROOT" && _chain_clean_env sbatch "${opts[@]}" "$script") ;;
    pbs)
      script=$MPIPD_ROOT/${MPIPD_JOB_SCRIPT:?MPIPD_JOB_SCRIPT (the script path) is needed to resubmit}
      # submitted without its array line (-J / -t): the next link is one plain job
      # for this case (MPIPD_CASE_INDEX); qsub reads the script from stdin
      jid=$(cd "$MPIPD_ROOT" && sed -E '/^#PBS[[:space:]]+-[Jt][[:space:]]/d' "$script" \
              | qsub -V -N "${PBS_JOBNAME:-mpipd}") ;;
  esac
  [ -n "$jid" ] || { _chain_log "stop: could not submit the next link"; exit 1; }
  _chain_log "submitted the next link as job $jid"
  exit 0
}

# ---------------------------------------------------------------- entry points

mpipd_job_run() {
  mpipd_job_start
  [ -n "${MPIPD_SCENE:-}" ] || _chain_die "no scene (set MPIPD_SCENE)"
  local out=${MPIPD_OUT:-runs/${MPIPD_SCENE//[:\/]/_}}
  # shellcheck disable=SC2086
  mpipd_chain_run "$out" "$MPIPD_SCENE" ${MPIPD_ARGS:-}
}

# the cases of a sweep: names in _CASE_NAMES, scene args in _CASE_SCENES,
# extra mpipd args in _CASE_ARGS (one string each)
_chain_cases() {
  _CASE_NAMES=(); _CASE_SCENES=(); _CASE_ARGS=()
  if [ -n "${MPIPD_CASES_FILE:-}" ]; then
    local f=$MPIPD_CASES_FILE name rest
    [ -f "$f" ] || f=$MPIPD_ROOT/$f
    [ -f "$f" ] || _chain_die "MPIPD_CASES_FILE $MPIPD_CASES_FILE not found"
    while read -r name rest || [ -n "$name" ]; do
      case $name in ''|'#'*) continue ;; esac
      _CASE_NAMES+=("$name"); _CASE_SCENES+=("$MPIPD_SCENE"); _CASE_ARGS+=("$rest")
    done <"$f"
  else
    local list=${MPIPD_CASES:-} c
    [ "$list" = all ] && list=$(mpipd cases "$MPIPD_SCENE")
    for c in $list; do
      _CASE_NAMES+=("$c"); _CASE_SCENES+=("$MPIPD_SCENE:$c"); _CASE_ARGS+=("")
    done
  fi
  (( ${#_CASE_NAMES[@]} > 0 )) || _chain_die "no cases (set MPIPD_CASES or MPIPD_CASES_FILE)"
}

mpipd_job_sweep() {
  mpipd_job_start
  _chain_cases
  local i n=${#_CASE_NAMES[@]}
  i=$(_chain_array_index)
  [ -n "$i" ] || _chain_die "not an array task: submit with --array=0-$((n - 1)) (SLURM) or -J 0-$((n - 1)) (PBS)"
  (( i >= 0 && i < n )) || _chain_die "array index $i outside the $n cases (${_CASE_NAMES[*]}): use indices 0-$((n - 1))"
  if [ "$MPIPD_SCHED" = slurm ] && [ -n "${SLURM_ARRAY_TASK_MAX:-}" ] && [ -z "${MPIPD_CASE_INDEX:-}" ] \
     && (( SLURM_ARRAY_TASK_MAX != n - 1 )); then
    echo "mpipd-job: warning: $n cases but the array ends at $SLURM_ARRAY_TASK_MAX" >&2
  fi
  local out=${MPIPD_OUT:-runs/${MPIPD_SCENE//[:\/]/_}}
  echo "mpipd-job: case $i of $n: ${_CASE_NAMES[i]} -> $out/${_CASE_NAMES[i]}"
  # shellcheck disable=SC2086
  mpipd_chain_run "$out/${_CASE_NAMES[i]}" "${_CASE_SCENES[i]}" ${MPIPD_ARGS:-} ${_CASE_ARGS[i]}
}

# mpipd_job_postprocess [RUN_DIR...]: python -m mpipd.post on each finished run
mpipd_job_postprocess() {
  trap - USR1 TERM
  mpipd_job_start
  local runs=("$@")
  if (( ${#runs[@]} == 0 )) && [ -n "${MPIPD_RUN:-}" ]; then
    # shellcheck disable=SC2206
    runs=($MPIPD_RUN)
  fi
  if (( ${#runs[@]} == 0 )) && [ -n "$(_chain_array_index)" ]; then    # a sweep's case
    _chain_cases
    local out=${MPIPD_OUT:-runs/${MPIPD_SCENE//[:\/]/_}}
    runs=("$out/${_CASE_NAMES[$(_chain_array_index)]}")
  fi
  (( ${#runs[@]} > 0 )) || _chain_die "no run folder (give RUN_DIR or set MPIPD_RUN)"
  local run st rc=0 args expanded=() d
  for run in "${runs[@]}"; do               # a folder of run folders: each of them
    run=${run%/}
    if [ ! -e "$run/run.h5" ] && compgen -G "$run/*/run.h5" >/dev/null; then
      for d in "$run"/*/run.h5; do expanded+=("${d%/run.h5}"); done
    else
      expanded+=("$run")
    fi
  done
  for run in "${expanded[@]}"; do
    read -r st _ _ <<<"$(_chain_state "$run")"
    if [ "$st" != "done" ]; then
      echo "mpipd-job: error: $run is not a finished run ($st)" >&2; rc=1; continue
    fi
    args=${MPIPD_POSTPROCESS_ARGS-"--out {run}/report"}
    args=${args//\{run\}/$run}
    echo "mpipd-job: $MPIPD_LAUNCHER python -m mpipd.post $MPIPD_POSTPROCESS $run/run.h5 $args"
    # shellcheck disable=SC2086
    $MPIPD_LAUNCHER "$(command -v python)" -m mpipd.post $MPIPD_POSTPROCESS "$run/run.h5" $args \
      > >(tee "$run/postprocess.log") 2>&1 || rc=1
    wait
  done
  return $rc
}
