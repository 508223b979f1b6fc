# The armfault image the Kubernetes recipe runs (deploy/k8s/):
#   docker build -t registry.example.com/armfault:0.1.0 . && docker push registry.example.com/armfault:0.1.0
# Stage 1 builds with tools/bootstrap.sh's build_packages (the main job's: no test-only or
# Python packages; nodejs and npm fetch the report's plotting libraries, reports/web); stage 2 holds the binary, the shipped campaigns and their schema
# (share/armfault/) and the runtime libraries only. tests/deploy/deploy_test.sh keeps both lists
# honest.
FROM debian:bookworm-slim AS build
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
      build-essential cmake pkg-config nodejs npm libode-dev libeigen3-dev libtbb-dev nlohmann-json3-dev libcli11-dev libssl-dev zlib1g-dev libisal-dev liburdfdom-dev libtinyxml-dev libboost-math-dev \
 && rm -rf /var/lib/apt/lists/*
WORKDIR /src
COPY . .
# The report's plotting libraries as locked (reports/web/package-lock.json), inlined by the build.
RUN cd reports/web && npm ci --ignore-scripts --no-audit --no-fund
RUN cmake -S . -B /build -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DARMFAULT_BUILD_BENCH=OFF \
 && cmake --build /build -j "$(nproc)" --target armfault \
 && cmake --install /build --prefix /usr/local

FROM debian:bookworm-slim
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends libode8 libtbb12 libssl3 zlib1g libisal2 liburdfdom-model3.0 libtinyxml2.6.2v5 \
 && rm -rf /var/lib/apt/lists/*
COPY --from=build /usr/local/bin/armfault /usr/local/bin/armfault
COPY --from=build /usr/local/share/armfault /usr/local/share/armfault
ENTRYPOINT ["armfault"]
CMD ["--version"]
