# cube5 — the README's two commands are `make demo` and `make test`; both run `setup` first.
CARGO ?= cargo
DEMO_DIR ?= out

.PHONY: setup demo test sim sim-full lint synth synth-full bench bench-accel bench-peer tradeoff regs fmt clippy clean clean-cache
.PHONY: cosim

# The build cache of verilated and compiled RTL variants (shared by every clone on the machine).
CUBE5_CACHE ?= $(if $(XDG_CACHE_HOME),$(XDG_CACHE_HOME),$(HOME)/.cache)/cube5

setup:
	@scripts/setup.sh

## The main job on the embedded default scene (no download): the model's image, then one frame
## of the RTL (cube5_frame, 4 pipelines) co-simulated against the model, bit for bit. Only that
## RTL configuration (cube5_frame with P = 4, 128^3) is built for it.
demo: setup
	@mkdir -p $(DEMO_DIR)
	CUBE5_TOPS=cube5_frame@P=4:MaxDim=128 $(CARGO) run --release -q -p cube5-cli -- render -o $(DEMO_DIR)/cube5-demo.png
	CUBE5_TOPS=cube5_frame@P=4:MaxDim=128 $(CARGO) run --release -q -p cube5-cli -- cosim -o $(DEMO_DIR)/cosim

## Every test: golden model, co-simulation (RTL and gate-level netlists), command line.
test: setup
	$(CARGO) test --release --workspace

## The RTL regression alone: every co-simulation test that CI runs. `make sim TOP=cube5_trilin`
## builds only that top's variants and runs its tests (tb-rs/tests/<top>.rs). The build prints
## which variants it built and which it reused from the cache.
sim: setup
ifdef TOP
	CUBE5_TOPS=$(TOP) $(CARGO) test --release -p cube5-tb --test $(TOP)
else
	$(CARGO) test --release -p cube5-tb
endif

## Everything in `sim` plus the runs too long for CI (tests marked #[ignore = "sim-full: ..."]).
sim-full: setup
	CUBE5_FULL=1 $(CARGO) test --release -p cube5-tb -p cube5-cli -- --include-ignored

## Scene-driven elaboration (docs/scenes.md, "What a scene builds"): `make cosim SCENE=scenes/head-mip.toml`
## prints the cube5_frame configuration the scene needs and why (`cube5 elaborate`), its area from
## Yosys synth_ecp5 against the full frame (cached; AREA=0 leaves it out), builds exactly that
## configuration (CUBE5_TOPS=cube5_frame@...: a generated variant where no .variants line has it,
## cached like any other) and co-simulates the scene on it. The elaboration runs from a cube5
## without the RTL (target/elab), so working it out builds no variant.
ELAB_CUBE5 = CARGO_TARGET_DIR=target/elab $(CARGO) run -q --release -p cube5-cli --no-default-features --
AREA ?= 1
cosim: setup
	@test -n "$(SCENE)" || { echo "usage: make cosim SCENE=scenes/head-mip.toml [AREA=0] [COSIM_OUT=dir]"; exit 2; }
	@spec=$$($(ELAB_CUBE5) elaborate --spec $(SCENE)) && \
	  $(ELAB_CUBE5) elaborate $(if $(filter 1,$(AREA)),--area) $(SCENE) && \
	  echo "make cosim: CUBE5_TOPS=$$spec" && \
	  CUBE5_TOPS=$$spec $(CARGO) run -q --release -p cube5-cli -- cosim $(SCENE) -o $(or $(COSIM_OUT),$(DEMO_DIR)/cosim-elab)

lint:
	@scripts/lint.sh

## synth-docs.sh: SYNTH_WRITE_DOCS=1 rewrites, SYNTH_CHECK_DOCS=1 checks the generated ECP5 table
## in docs/measurements.md (issue 17).
synth:
	@scripts/synth.sh
	@scripts/synth-docs.sh

## synth plus the `synthfull` configurations (the 256^3 accelerator: tens of minutes of Yosys and
## place and route, beyond CI's synthesis budget; their rows of the generated table stay as this
## run writes them). With SYNTH_FLOWS=ecp5 SYNTH_WRITE_DOCS=1 it refreshes those rows.
synth-full:
	@SYNTH_FULL=1 scripts/synth.sh
	@SYNTH_FULL=1 scripts/synth-docs.sh

## Simulation-speed figures come from RTL variants compiled at C++ -O2 (tests use -O1, which
## builds twice as fast; docs/ci.md). The -O2 objects are cached beside the -O1 ones.
bench: setup
	CUBE5_RTL_CXX_OPT=-O2 $(CARGO) run --release -q -p cube5-cli -- bench

## The accelerator's whole-frame benchmark (docs/accel.md, *Measured*): cube5_accel's MaxDim 256
## configurations at P = 1, 2, 4, 8 (`full` lines, minutes of build each) render the 128^3 and
## 256^3 head with the DDR-like memory; prints the table (cycles, samples/clock/pipeline, frames/s
## at the units' lowest placed Fmax) and writes it to target/bench-accel.md.
bench-accel: setup
	CUBE5_FULL=1 CUBE5_TOPS=cube5_accel $(CARGO) test --release -p cube5-tb --test cube5_accel -- --ignored --nocapture benchmark_table

## The peer benchmark (issue 13): cube5's model against VTK's vtkFixedPointVolumeRayCastMapper on
## the same 256^3 volume, transfer function and view, with both times and their ratio
## (docs/measurements.md, "Peer"). Makes .venv-peer with the pinned VTK from PyPI (and Mesa's EGL
## with apt-get if VTK cannot render offscreen); images go to target/bench-peer/. Options of the
## script: `make bench-peer PEER_ARGS="--pixels 256 --threads 2"`.
bench-peer: setup
	@scripts/setup_peer.sh
	CUBE5_TOPS=$${CUBE5_TOPS:-cube5_trilin} $(CARGO) build --release -q -p cube5-cli
	.venv-peer/bin/python scripts/bench_peer.py --cube5 $${CARGO_TARGET_DIR:-target}/release/cube5 $(PEER_ARGS)

## Regenerates docs/tradeoffs.md and its plots (speed/area against accuracy sweeps).
tradeoff: setup
	$(CARGO) run --release -q -p cube5-cli -- tradeoff --write-docs

## Regenerates the register maps and shared constants from rtl/**/*.regs.toml (SV packages, model/src/regs, docs tables).
regs:
	$(CARGO) run -q -p cube5-gen -- regs --write

fmt:
	$(CARGO) fmt --all

clippy:
	$(CARGO) clippy --workspace --all-targets --release -- -D warnings
	$(CARGO) clippy -p cube5-cli --all-targets --release --no-default-features -- -D warnings

clean:
	$(CARGO) clean
	rm -rf $(DEMO_DIR)

## Empties the build cache of RTL variants (every variant is rebuilt on the next build).
clean-cache:
	rm -rf $(CUBE5_CACHE)
