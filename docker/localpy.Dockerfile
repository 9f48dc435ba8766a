# Python 3.11 on the debootstrapped Debian bookworm image (docker/local-base.sh):
# what python:3.11-slim gives users, built without a registry.
FROM localbase:bookworm
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3 python3-venv \
 && rm -rf /var/lib/apt/lists/* \
 && ln -s /usr/bin/python3 /usr/local/bin/python
