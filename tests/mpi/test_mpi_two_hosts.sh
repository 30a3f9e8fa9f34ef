#!/usr/bin/env bash
# Two "hosts" on this machine: two network namespaces joined by a veth pair,
# one rank in each, Open MPI between them over TCP only (no shared memory),
# its daemon started in the second namespace by an rsh agent instead of ssh.
# The image equals paprsek render's, the scene being only in rank 0's folder.
# Needs root and network namespaces (ip netns); skipped otherwise.
# usage: test_mpi_two_hosts.sh PAPRSEK PAPRSEK_MPI MPIEXEC DATA_DIR
. "$(dirname "$0")/mpi_common.sh"
unset OMPI_MCA_btl_tcp_if_include OMPI_MCA_oob_tcp_if_include

[ "$(id -u)" = 0 ] || { echo "SKIP: network namespaces need root"; exit 77; }
command -v ip >/dev/null || { echo "SKIP: no ip command (iproute2)"; exit 77; }
a=pk$$a b=pk$$b
if ! ip netns add "$a" 2>"$tmp/e"; then
  echo "SKIP: network namespaces are not permitted here: $(cat "$tmp/e")"
  exit 77
fi
ip netns add "$b"
trap 'ip netns del "$a" 2>/dev/null; ip netns del "$b" 2>/dev/null; rm -rf "$tmp"' EXIT
# the subnet: 10.77.x.0/24 from the process id, so that two runs do not meet
net=10.77.$(($$ % 250)).
ip link add "v$$a" type veth peer name "v$$b" &&
  ip link set "v$$a" netns "$a" && ip link set "v$$b" netns "$b" &&
  ip netns exec "$a" ip addr add "${net}1/24" dev "v$$a" && ip netns exec "$b" ip addr add "${net}2/24" dev "v$$b" &&
  ip netns exec "$a" ip link set "v$$a" up && ip netns exec "$b" ip link set "v$$b" up &&
  ip netns exec "$a" ip link set lo up && ip netns exec "$b" ip link set lo up ||
  { echo "SKIP: cannot join two network namespaces with a veth pair"; exit 77; }

# mpirun's rsh agent: "HOST COMMAND" runs COMMAND in HOST's namespace, and
# notes which namespace it entered
cat >"$tmp/agent.sh" <<AGENT
#!/bin/sh
host=\$1; shift
case "\$host" in ${net}1) ns=$a;; ${net}2) ns=$b;; *) echo "unknown host \$host" >&2; exit 1;; esac
echo "\$ns" >>"$tmp/agent.log"
exec ip netns exec "\$ns" sh -c "\$*"
AGENT
chmod +x "$tmp/agent.sh"
printf '%s slots=1\n%s slots=1\n' "${net}1" "${net}2" >"$tmp/hosts"

opts=(--width 48 --height 32 --spp 3 --threads 1 --look-from 0,1.5,5 --look-at 0,1,0)
args=(mpi_room.obj -o "$tmp/two.pfm" "${opts[@]}" --tile 16 --stats)
(cd "$tmp/scene" && "$bin" render mpi_room.obj -o "$tmp/one.pfm" "${opts[@]}" --quiet) || bad "paprsek render"
timeout 120 ip netns exec "$a" "$mpiexec" --hostfile "$tmp/hosts" --mca plm_rsh_agent "$tmp/agent.sh" \
  --mca btl tcp,self --mca btl_tcp_if_include "${net}0/24" --mca oob_tcp_if_include "${net}0/24" --bind-to none \
  -np 1 -wdir "$tmp/scene" "$mpi" render "${args[@]}" : -np 1 -wdir "$tmp/empty" "$mpi" render "${args[@]}" \
  >"$tmp/stats" 2>"$tmp/e"
st=$?
if [ $st != 0 ]; then
  bad "two hosts: exit status $st"
  cat "$tmp/e"
else
  cmp -s "$tmp/one.pfm" "$tmp/two.pfm" || bad "two hosts: the image differs from paprsek render's"
  grep -qx "$b" "$tmp/agent.log" 2>/dev/null || bad "two hosts: no daemon was started in the second namespace"
  t1=$(awk '$1 == "rank" && $2 == 1 { for (i = 1; i <= NF; i++) if ($i == "tiles") print $(i - 1) }' "$tmp/stats")
  [ -n "$t1" ] || bad "two hosts: --stats does not list rank 1"
  echo "rank 1 (second namespace) rendered ${t1:-?} of 6 tiles"
fi
[ $fail = 0 ] && echo "test_mpi_two_hosts: ok"
exit $fail
