#!/usr/bin/env bash
# Build a Python 3.11 base image without pulling from a registry (none is
# reachable on the machines that test this project): debootstrap a Debian
# bookworm root file system, import it, and add Python on top.
#   docker/local-base.sh [TAG]      (default localpy:3.11; needs root, docker, debootstrap)
set -euo pipefail
tag=${1:-localpy:3.11}
here=$(cd "$(dirname "$0")" && pwd)
if docker image inspect "$tag" >/dev/null 2>&1; then
    echo "base image $tag already exists"
    exit 0
fi
if ! docker image inspect localbase:bookworm >/dev/null 2>&1; then
    rootfs=$(mktemp -d /tmp/swarm-rootfs.XXXXXX)
    trap 'rm -rf "$rootfs"' EXIT
    echo "debootstrap bookworm into $rootfs (about a minute)"
    debootstrap --variant=minbase bookworm "$rootfs" http://deb.debian.org/debian >/tmp/swarm-debootstrap.log 2>&1 \
        || { tail -20 /tmp/swarm-debootstrap.log; exit 1; }
    tar -C "$rootfs" -c . | docker import - localbase:bookworm >/dev/null
fi
docker build --quiet -t "$tag" -f "$here/localpy.Dockerfile" "$here" >/dev/null
echo "built base image $tag"
