# Placeholder until the deployment issue: builds the CLI and runs the test suite in a
# debian:bookworm build stage, and ships only the CLI in the runtime stage. Not yet exercised in CI.
FROM debian:bookworm AS build
WORKDIR /src
COPY . .
RUN bash scripts/install-deps.sh \
 && cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
 && ninja -C build \
 && ctest --test-dir build --output-on-failure

FROM debian:bookworm
RUN apt-get update && apt-get install -y --no-install-recommends libabsl20220623 zlib1g \
 && rm -rf /var/lib/apt/lists/* && useradd --system --uid 10001 geodex
COPY --from=build /src/build/client/geodex /usr/local/bin/geodex
USER geodex
ENTRYPOINT ["geodex"]
CMD ["--help"]
