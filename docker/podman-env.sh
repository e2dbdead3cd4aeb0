# Sourced (`. docker/podman-env.sh`) before podman or podman-compose builds or runs the image, so
# that rootful podman can start containers on sandboxed machines such as CI's:
# - podman gives a root container nofile=1048576 and raises nproc past what its own process may
#   have; a root without CAP_SYS_RESOURCE cannot raise a hard limit, and runc then fails with
#   "error setting rlimits". Containers get this shell's hard limit of open files, and podman's
#   usual 32768 processes (or this shell's hard limit, if lower).
# - runc, not crun: crun, which podman prefers when both are installed, cannot start containers on
#   some cgroup v1 hosts.
# podman-compose 1.0 passes no global podman options through, so both go into a containers.conf
# that CONTAINERS_CONF names (it stands in for /etc/containers/containers.conf for these commands).
# A CONTAINERS_CONF already set is kept: that machine's configuration wins.
if [ -z "${CONTAINERS_CONF:-}" ]; then
  tessera_ulimits=()
  tessera_hard=$(ulimit -Hn)
  if [ "$tessera_hard" != unlimited ]; then
    tessera_ulimits+=("\"nofile=$tessera_hard:$tessera_hard\"")
  fi
  tessera_hard=$(ulimit -Hu)
  if [ "$tessera_hard" = unlimited ] || [ "$tessera_hard" -gt 32768 ]; then tessera_hard=32768; fi
  tessera_ulimits+=("\"nproc=$tessera_hard:$tessera_hard\"")
  TESSERA_CONTAINERS_CONF=$(mktemp "${TMPDIR:-/tmp}/tessera-containers.XXXXXX")
  {
    echo "[containers]"
    (IFS=,; echo "default_ulimits = [${tessera_ulimits[*]}]")
    echo "[engine]"
    echo "runtime = \"runc\""
  } >"$TESSERA_CONTAINERS_CONF"
  export CONTAINERS_CONF="$TESSERA_CONTAINERS_CONF"
  unset tessera_ulimits tessera_hard
fi
