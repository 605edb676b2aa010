# HAProxy from Debian with deploy/haproxy.cfg: the gRPC proxy in front of tubepick-server replicas
# (deploy/docker-compose.yml). Built and run by CI (deploy/test-image.sh).
#
#   podman build --format docker -f deploy/haproxy.Dockerfile -t tubepick-proxy .   (repository root)
FROM debian:bookworm-slim
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends haproxy >/dev/null \
 && apt-get clean && rm -rf /var/lib/apt/lists/* /var/cache/apt/*.bin /var/log/apt /var/log/dpkg.log
COPY deploy/haproxy.cfg /etc/haproxy/haproxy.cfg
USER haproxy
# -W: master-worker (SIGUSR2 reloads the file); -db: stay in the foreground, log to stdout.
STOPSIGNAL SIGUSR1
ENTRYPOINT ["haproxy", "-W", "-db", "-f", "/etc/haproxy/haproxy.cfg"]
