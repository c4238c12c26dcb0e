# Measurement targets (issue 7; DESIGN.md §8). Both print their figures and write CSV.
#
#   make -f pipelines/bench.mk tables   [BENCH_FRAMES=400] [BENCH_SIZE=352x240] [BENCH_ONLY=cubes-1,cubes-32] [BENCH_REFERENCE_SPP=128]
#       (BENCH_ONLY=cornell-moving BENCH_FRAMES=96: the bundled scene, per stage)
#       the paper's Tables 2-5: every configuration coherent and from scratch (same binaries,
#       one run), total and per-frame time, speed-up, peak memory, links updated per key;
#       coherent and scratch against two rad-reference renders at one frame (0: skip);
#       out/bench/tables.csv
#   make -f pipelines/bench.mk tradeoff [TRADEOFF_FRAMES=0-47] [TRADEOFF_SIZE=176x120] [TRADEOFF_SPP=128] [TRADEOFF_REPEAT=3]
#       each accuracy knob swept against a converged rad-reference render: time per frame vs
#       RMSE, Pareto front; out/tradeoff/tradeoff.csv and tradeoff.png (gnuplot)

BIN ?= build/bin
BENCH_FRAMES ?= 400
BENCH_SIZE ?= 352x240
BENCH_ONLY ?=
BENCH_REFERENCE_SPP ?= 128
TRADEOFF_SCENE ?= pipelines/scenes/cornell-moving.gltf
TRADEOFF_FRAMES ?= 0-47
TRADEOFF_SIZE ?= 176x120
TRADEOFF_SPP ?= 128
TRADEOFF_REPEAT ?= 3

.PHONY: tables tradeoff
tables:
	python3 pipelines/bench.py --bin $(BIN) --frames $(BENCH_FRAMES) --size $(BENCH_SIZE) \
	  $(if $(BENCH_ONLY),--only $(BENCH_ONLY)) --reference-spp $(BENCH_REFERENCE_SPP) --out out/bench

tradeoff:
	python3 pipelines/tradeoff.py --bin $(BIN) --scene $(TRADEOFF_SCENE) --frames $(TRADEOFF_FRAMES) \
	  --size $(TRADEOFF_SIZE) --spp $(TRADEOFF_SPP) --repeat $(TRADEOFF_REPEAT) --out out/tradeoff
