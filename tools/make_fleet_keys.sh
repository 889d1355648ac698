#!/usr/bin/env bash
# Generates per-sender Ed25519 key files for a fleet (docs/security.md §5): one owner-only
# file per sender id, holding that node's signing key and every other sender's verifying
# (public) key, all with key id KEY_ID (default 1).
#   tools/make_fleet_keys.sh OUT_DIR SENDER_ID...      e.g. tools/make_fleet_keys.sh /tmp/keys 0 1 2 100
#   KEY_ID=2 tools/make_fleet_keys.sh ...              (the next key of a rotation)
# Writes OUT_DIR/sender_<id>.key (mode 0600). Secret seeds never leave OUT_DIR (umask 077).
case "${1:-}" in -h | --help | "") awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -euo pipefail
umask 077
out=$1
shift
[ $# -ge 1 ] || { echo "make_fleet_keys.sh: give at least one sender id" >&2; exit 2; }
key_id=${KEY_ID:-1}
mkdir -p "$out"
declare -A seed pub
for id in "$@"; do
  [[ $id =~ ^[0-9]+$ ]] && [ "$id" -le 65535 ] || { echo "make_fleet_keys.sh: sender id '$id' is not 0..65535" >&2; exit 2; }
  pem=$(openssl genpkey -algorithm ed25519)
  # DER of an Ed25519 private key: 16-byte prefix + 32-byte seed; public key: 12 + 32.
  seed[$id]=$(printf '%s\n' "$pem" | openssl pkey -outform DER | tail -c 32 | od -An -v -tx1 | tr -d ' \n')
  pub[$id]=$(printf '%s\n' "$pem" | openssl pkey -pubout -outform DER | tail -c 32 | od -An -v -tx1 | tr -d ' \n')
done
for id in "$@"; do
  f="$out/sender_$id.key"
  {
    echo "# sender $id: its signing key, then every other sender's verifying key (key id $key_id)"
    echo "$key_id ${seed[$id]} signing sender=$id active"
    for peer in "$@"; do
      [ "$peer" = "$id" ] || echo "$key_id ${pub[$peer]} verifying sender=$peer"
    done
  } > "$f"
  chmod 600 "$f"
done
echo "make_fleet_keys.sh: wrote $(printf "$out/sender_%s.key " "$@")"
