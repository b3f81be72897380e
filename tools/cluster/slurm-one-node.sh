#!/bin/bash
# Starts a one-node Slurm cluster on this machine, for trying `glint farm
# slurm` and for cli/tests/farm_slurm.rs (which runs it itself): munge for authentication, a
# slurm.conf with this machine as the only node (all its CPUs, processes
# tracked without cgroups), then slurmctld and slurmd as plain daemons. It
# needs root, and no systemd (it works in a container).
#
#   sudo tools/cluster/slurm-one-node.sh          # install if needed, start
#   sudo tools/cluster/slurm-one-node.sh --stop   # stop the daemons
#
# Debian or Ubuntu: installs slurm-wlm and munge with apt-get if missing.
set -euo pipefail

if [ "${1:-}" = "--stop" ]; then
  pkill -x slurmd || true
  pkill -x slurmctld || true
  pkill -x munged || true
  echo "slurm-one-node: stopped"
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "slurm-one-node: run as root (it installs packages and starts daemons)" >&2
  exit 2
fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y slurm-wlm munge
fi

# munge: a key, and the daemon (as the munge user, as it insists).
if [ ! -s /etc/munge/munge.key ]; then
  mungekey --create --force
fi
chown munge:munge /etc/munge/munge.key
chmod 400 /etc/munge/munge.key
mkdir -p /run/munge /var/log/munge /var/lib/munge
chown munge:munge /run/munge /var/log/munge /var/lib/munge
if ! pgrep -x munged >/dev/null; then
  runuser -u munge -- /usr/sbin/munged
fi

node=$(hostname -s)
cpus=$(nproc)
# Leave the system 512 MiB.
memory=$(( $(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 512 ))
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
cat > /etc/slurm/slurm.conf <<CONF
# Written by glint's tools/cluster/slurm-one-node.sh: one node, this machine.
ClusterName=glint
SlurmctldHost=$node
SlurmUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
# A task told to stop (a requeue, a time limit) gets SIGTERM, then this long
# before SIGKILL: glint writes the tile's finished pixels in well under it.
KillWait=30
NodeName=$node CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF

if ! pgrep -x slurmctld >/dev/null; then
  slurmctld -i
fi
if ! pgrep -x slurmd >/dev/null; then
  slurmd
fi
for _ in $(seq 1 50); do
  state=$(sinfo --noheader --format=%T 2>/dev/null | head -1 || true)
  case "$state" in
    idle|mixed|allocated)
      echo "slurm-one-node: node $node up ($cpus CPUs, $memory MiB), partition main"
      exit 0
      ;;
  esac
  sleep 0.2
done
echo "slurm-one-node: the node did not come up; see /var/log/slurm/slurmctld.log and slurmd.log" >&2
exit 1
