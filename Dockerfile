# contactfx on Debian 13 (dolfinx 0.9, PETSc 3.22, Open MPI 5).
#   docker build -t contactfx .
#   docker run --rm -v "$PWD/results:/results" contactfx          # default scene -> results/hertz2d
#   docker run --rm contactfx make test
# scripts/chroot-debian13.sh runs these same steps without Docker (it interprets FROM, COPY,
# WORKDIR, ENV and RUN), so keep RUN lines in shell form.
FROM debian:trixie

# Open MPI in a single-node container: allowed as root, more ranks than cores allowed
# (OMPI_MCA_* for Open MPI 4, PRTE_MCA_* for 5), TCP only on loopback (the shared-memory
# transport carries the traffic; Open MPI 5 otherwise warns about unreachable interfaces).
# One BLAS/OpenMP thread per rank.
ENV OMPI_ALLOW_RUN_AS_ROOT=1 \
    OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
    OMPI_MCA_rmaps_base_oversubscribe=1 \
    PRTE_MCA_rmaps_default_mapping_policy=:oversubscribe \
    OMPI_MCA_btl_tcp_if_include=lo \
    OPENBLAS_NUM_THREADS=1 \
    OMP_NUM_THREADS=1

COPY . /opt/contactfx
WORKDIR /opt/contactfx
RUN bash scripts/install.sh && apt-get clean && rm -rf /var/lib/apt/lists/*

ENV PATH=/opt/contactfx/.venv/bin:$PATH
CMD ["mpirun", "-n", "2", "contactfx", "run", "hertz2d", "--out", "/results/hertz2d"]
