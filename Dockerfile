# geodex container image: geodexd (the service) and geodex (the CLI, also the health check).
#
#   docker build --network host -t geodex .
#   docker build --network host --build-arg GEODEX_TESTS=ON -t geodex .   (also runs the suite)
#   docker run -d --network host -v geodex-data:/data geodex --listen=127.0.0.1:50051
#
# Stage 1 builds the two binaries (with GEODEX_TESTS=ON: everything, and runs the whole test suite
# inside debian:bookworm; CI runs that suite on the same sources before it builds the image, so its
# smoke build leaves it off); stage 2 holds only the two binaries and their runtime libraries, runs
# as a non-root user and keeps meshes in the /data volume.
# Ports: 50051 gRPC (geodex.v1, health, reflection), 9464 Prometheus /metrics.
# Flags: every geodexd flag may follow the image name (see the flag table in docs/service.md); the defaults
# below listen on all interfaces of the container, as Kubernetes pods need.

FROM debian:bookworm AS build
WORKDIR /src
COPY scripts/install-deps.sh scripts/install-deps.sh
RUN GEODEX_NO_BROWSER=1 bash scripts/install-deps.sh && rm -rf /var/lib/apt/lists/*
COPY . .
ARG GEODEX_TESTS=OFF
RUN cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DGEODEX_BUILD_BENCH=OFF \
      -DGEODEX_BUILD_TESTS="$GEODEX_TESTS" \
 && if [ "$GEODEX_TESTS" = ON ]; then \
      ninja -C build && ctest --test-dir build --output-on-failure -j 2; \
    else \
      ninja -C build geodexd geodex; \
    fi

FROM debian:bookworm
RUN apt-get update \
 && apt-get install -y --no-install-recommends libgrpc++1.51 libprotobuf32 libabsl20220623 \
      libspdlog1.10 libprometheus-cpp-pull1.0 libprometheus-cpp-core1.0 libcivetweb1 libpng16-16 zlib1g libssl3 libgdal32 libgeos-c1v5 \
 && rm -rf /var/lib/apt/lists/* \
 && groupadd --system --gid 10001 geodex \
 && useradd --system --uid 10001 --gid geodex --home-dir /data --shell /usr/sbin/nologin geodex \
 && mkdir /data && chown geodex:geodex /data
COPY --from=build /src/build/server/geodexd /src/build/client/geodex /usr/local/bin/
USER 10001:10001
VOLUME /data
# Two malloc arenas instead of glibc's default 8 per core: under load geodexd's peak RSS was 440 MiB
# with the default and 303 MiB with 2, at the same throughput (docs/reliability.md, "Load").
ENV MALLOC_ARENA_MAX=2
EXPOSE 50051 9464
# geodexd drains on SIGTERM (health NOT_SERVING, running calls get --shutdown_grace_seconds, 10 s by
# default) and exits 0, so `docker stop` is quick; as PID 1 it handles the signal itself.
STOPSIGNAL SIGTERM
# The gRPC health service through the CLI (plaintext loopback). With another --listen port, override
# it: docker run --health-cmd "geodex --server 127.0.0.1:PORT health" ...
HEALTHCHECK --interval=10s --timeout=5s --start-period=60s --retries=3 \
  CMD ["geodex", "--server", "127.0.0.1:50051", "health"]
ENTRYPOINT ["geodexd", "--data_dir=/data"]
CMD ["--listen=0.0.0.0:50051", "--metrics_listen=0.0.0.0:9464"]
