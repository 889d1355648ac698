#!/bin/bash
# tools/setup.sh stops with a clear message on anything but Debian 12, before installing.
SRC=$2
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
printf 'PRETTY_NAME="Ubuntu 22.04.4 LTS"\nID=ubuntu\nVERSION_ID="22.04"\n' > "$T/os-release"
out=$(GF_OS_RELEASE="$T/os-release" "$SRC/tools/setup.sh" 2>&1); code=$?
echo "$out"
[ $code -ne 0 ] || { echo "FAIL: setup accepted Ubuntu"; exit 1; }
echo "$out" | grep -q "unsupported OS 'Ubuntu 22.04.4 LTS'.*Debian 12" || { echo "FAIL: message"; exit 1; }
out=$(GF_OS_RELEASE="$T/missing" "$SRC/tools/setup.sh" 2>&1); code=$?
[ $code -ne 0 ] && echo "$out" | grep -q "cannot read" || { echo "FAIL: missing os-release"; exit 1; }
