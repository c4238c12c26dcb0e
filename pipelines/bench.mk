# Measurement targets (issue 7; docs/design.md §8). Both print their figures and write CSV.
#
#   make -f pipelines/bench.mk tables   [BENCH_FRAMES=400] [BENCH_SIZE=352x240] [BENCH_ONLY=cubes-1,cubes-32] [BENCH_REFERENCE_SPP=128]
#       (BENCH_ONLY=cornell-moving BENCH_FRAMES=96: the bundled scene, per stage)
#       the paper's Tables 2-5: every configuration coherent and from scratch (same binaries,
#       one run), total and per-frame time, speed-up, peak memory, links updated per key;
#       coherent and scratch against two rad-reference renders at one frame (0: skip);
#       out/bench/tables.csv
#   make -f pipelines/bench.mk tradeoff [TRADEOFF_SCENE=...] [TRADEOFF_FRAMES=0-47] [TRADEOFF_SIZE=176x120] [TRADEOFF_SPP=128] [TRADEOFF_REPEAT=3]
#                                       [TRADEOFF_EVAL_FRAME=20] [TRADEOFF_REFERENCES=DIR0,DIR1] [TRADEOFF_OUT=out/tradeoff]
#       each accuracy knob swept, and the draft and final presets, against a converged
#       rad-reference render: time per frame vs RMSE, Pareto front; TRADEOFF_OUT/tradeoff.csv
#       and tradeoff.png (gnuplot)
#   make -f pipelines/bench.mk scale [SCALE_TRIANGLES=1000,3000,10000,30000,100000] [SCALE_FRAMES=0-95] [SCALE_MAX_SECONDS=1800] [SCALE_MOVING_LIGHT=1]
#       the lecture hall of make_hall.py at each triangle count through the four stages: each
#       stage's time and peak memory, rad-global's links, the log-log slopes of links (at the
#       first key with no link bound: one more rad-global run a size, 3.2 GB at 100k) and of
#       rad-global's time against the triangle count; out/scale/scale.csv and scale.png
#   make -f pipelines/bench.mk million [MILLION_TRIANGLES=100000,1000000] [MILLION_FRAMES=0-95] [MILLION_MAX_SECONDS=7200]
#       issue 58's million triangles: make_floor.py's floor of furnished rooms (meshes shared by
#       many nodes) at each count through the four stages (pipelines/scale.py --scene floor):
#       triangles, each stage's time and peak memory, rad-global's links and its key times at
#       the link bound; out/million/scale.csv. Goals: 10^5 <= 4 min, 10^6 <= 40 min, every stage
#       <= 8 GB. Not a timed test: run it on a quiet machine
#   make -f pipelines/bench.mk farm-model [FARM_SCENE=pipelines/scenes/cornell-moving.gltf] [FARM_FRAMES=0-95] [FARM_NODES=1,4,16,64] [FARM_FLAGS=--global-windows]
#       one run of animation.mk on one core, then the wall time slurm.mk would take on N nodes
#       of this machine's size, its critical path and the serial part (pipelines/farm_model.py);
#       slurm.mk's default pieces and segments: FARM_FLAGS="--piece-keys 4 --video-segments";
#       --time-windows also times rad-global in two windows and their merge (docs/results.md,
#       "Window merges in the last window task")
#   make -f pipelines/bench.mk furnace [FURNACE_RHO=0.5,0.9,0.99,0.999] [FURNACE_FLAGS="global=--eps 1e-4"]
#       the closed furnace through the whole pipeline at each rho: frame mean against the exact
#       L_e / (1 - rho), time and peak memory; out/furnace/
#   make -f pipelines/bench.mk image [IMAGE_OWN=cornell-moving,...|none] [IMAGE_CORPUS=DIR] [IMAGE_FRAMES=0-24] [IMAGE_EVAL_FRAME=20] [IMAGE_SPP=1024] [IMAGE_PRESETS=default,final]
#       issue 56's figures per scene at the default and final presets (pipelines/image_figures.py):
#       RMSE / mean and bias (edges in, emitters out), edge and interior pixels apart, the
#       structured error and its reference floor, the largest seam step beyond the reference's,
#       against two rad-reference renders with the frames' filter; IMAGE_CORPUS adds the public
#       scenes of pipelines/corpus/scenes.py; out/image/image-figures.csv
#   make -f pipelines/bench.mk lights [LIGHTS_ONLY=closed,room,moving,heldout] [LIGHTS_SPP=512] [LIGHTS_FRAMES=96] [LIGHTS_REPEAT=3]
#       issue 57's figures for punctual lamps, each against its goal (pipelines/lights.py): closed
#       forms through the real tools (point, spot across its cones, sun, the closed box), the
#       Blender lamp room against Cycles, a moving lamp coherent against --no-coherence (bit-
#       identical) and its whole pipeline's speed-up, a held-out Blender scene against Cycles;
#       out/lights/lights.json
#   make -f pipelines/bench.mk corpus [CORPUS_SCENES=all|graz,soda|none] [CORPUS_DIR=out/corpus/scenes] [CORPUS_KEEP=REGEX]
#                                     [CORPUS_GENERATED=contact] [CORPUS_FRAMES=0-95] [CORPUS_SIZE=352x240]
#                                     [CORPUS_EVAL_FRAME=48] [CORPUS_SPP=256]
#       issue 58's figures per scene (pipelines/corpus_bench.py): the public scenes of
#       pipelines/corpus/scenes.py fetched and converted into CORPUS_DIR at benchmark time (never
#       committed), and generated ones; triangles, key times at the link bound, links and cluster
#       links, each stage's time and peak memory, RMSE / mean, bias, structured error and floor
#       against two rad-reference renders (image_figures.py's figures), each row checked against
#       the issue's goals, held-out scenes marked; out/corpus/corpus.csv
#   make -f pipelines/bench.mk fuzz [FUZZ_SECONDS=600] [FUZZ_RUNS=-1]
#       every reader's libFuzzer harness for FUZZ_SECONDS each, or until FUZZ_RUNS executions
#       (-1: no bound but the time; the issue's long run: FUZZ_RUNS=1000000 FUZZ_SECONDS=5400)
#       (tests/fuzz/run.sh, clang build in build-fuzz/): executions and crashes per harness;
#       reproducers in build-fuzz/fuzz-work/

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
TRADEOFF_OUT ?= out/tradeoff

SCALE_TRIANGLES ?= 1000,3000,10000,30000,100000
SCALE_FRAMES ?= 0-95
SCALE_MAX_SECONDS ?= 1800
SCALE_MOVING_LIGHT ?=
MILLION_TRIANGLES ?= 100000,1000000
MILLION_FRAMES ?= 0-95
MILLION_MAX_SECONDS ?= 7200

FARM_SCENE ?= pipelines/scenes/cornell-moving.gltf
FARM_FRAMES ?= 0-95
FARM_NODES ?= 1,4,16,64
FARM_FLAGS ?=

FURNACE_RHO ?= 0.5,0.9,0.99,0.999
FURNACE_FLAGS ?=

IMAGE_OWN ?=
IMAGE_CORPUS ?=
IMAGE_FRAMES ?= 0-24
IMAGE_EVAL_FRAME ?= 20
IMAGE_SPP ?= 1024
IMAGE_PRESETS ?= default,final

LIGHTS_ONLY ?= closed,room,moving,heldout
LIGHTS_SPP ?= 512
LIGHTS_FRAMES ?= 96
LIGHTS_REPEAT ?= 3
CORPUS_DIR ?= out/corpus/scenes
CORPUS_SCENES ?= all
CORPUS_KEEP ?=
CORPUS_GENERATED ?=
CORPUS_FRAMES ?= 0-95
CORPUS_SIZE ?= 352x240
CORPUS_EVAL_FRAME ?= 48
CORPUS_SPP ?= 256

FUZZ_SECONDS ?= 600
FUZZ_RUNS ?= -1

.PHONY: tables tradeoff furnace contact scale million farm-model image lights corpus fuzz
tables:
	python3 pipelines/bench.py --bin $(BIN) --frames $(BENCH_FRAMES) --size $(BENCH_SIZE) \
	  $(if $(BENCH_ONLY),--only $(BENCH_ONLY)) --reference-spp $(BENCH_REFERENCE_SPP) --out out/bench

tradeoff:
	python3 pipelines/tradeoff.py --bin $(BIN) --scene $(TRADEOFF_SCENE) --frames $(TRADEOFF_FRAMES) \
	  --size $(TRADEOFF_SIZE) --spp $(TRADEOFF_SPP) --repeat $(TRADEOFF_REPEAT) \
	  $(if $(TRADEOFF_EVAL_FRAME),--eval-frame $(TRADEOFF_EVAL_FRAME)) \
	  $(if $(TRADEOFF_REFERENCES),--references $(TRADEOFF_REFERENCES)) --out $(TRADEOFF_OUT)

contact:
	python3 pipelines/contact.py --bin $(BIN) --out out/contact

scale:
	python3 pipelines/scale.py --bin $(BIN) --triangles $(SCALE_TRIANGLES) --frames $(SCALE_FRAMES) \
	  --size $(BENCH_SIZE) --max-seconds $(SCALE_MAX_SECONDS) $(if $(SCALE_MOVING_LIGHT),--moving-light) \
	  --out out/scale$(if $(SCALE_MOVING_LIGHT),-moving-light)

million:
	python3 pipelines/scale.py --scene floor --no-unbounded --bin $(BIN) --triangles $(MILLION_TRIANGLES) \
	  --frames $(MILLION_FRAMES) --size $(BENCH_SIZE) --max-seconds $(MILLION_MAX_SECONDS) --out out/million

furnace:
	python3 pipelines/furnace.py --bin $(BIN) --rho $(FURNACE_RHO) --out out/furnace \
	  $(if $(FURNACE_FLAGS),--flags "$(FURNACE_FLAGS)")

farm-model:
	python3 pipelines/farm_model.py --bin $(BIN) --scene $(FARM_SCENE) --frames $(FARM_FRAMES) \
	  --size $(BENCH_SIZE) --nodes $(FARM_NODES) --out out/farm-model $(FARM_FLAGS)

image:
	python3 pipelines/image_figures.py --bin $(BIN) --frames $(IMAGE_FRAMES) --eval-frame $(IMAGE_EVAL_FRAME) \
	  --size $(BENCH_SIZE) --spp $(IMAGE_SPP) --presets $(IMAGE_PRESETS) --out out/image \
	  $(if $(IMAGE_OWN),--own $(IMAGE_OWN)) $(if $(IMAGE_CORPUS),--corpus $(IMAGE_CORPUS))

lights:
	python3 pipelines/lights.py --bin $(BIN) --only $(LIGHTS_ONLY) --spp $(LIGHTS_SPP) \
	  --moving-frames $(LIGHTS_FRAMES) --repeat $(LIGHTS_REPEAT) --out out/lights --check

corpus:
	python3 pipelines/corpus_bench.py --bin $(BIN) --out out/corpus --corpus $(CORPUS_DIR) \
	  --scenes $(CORPUS_SCENES) $(if $(CORPUS_KEEP),--keep '$(CORPUS_KEEP)') \
	  $(if $(CORPUS_GENERATED),--generated $(CORPUS_GENERATED)) --frames $(CORPUS_FRAMES) \
	  --size $(CORPUS_SIZE) --eval-frame $(CORPUS_EVAL_FRAME) --spp $(CORPUS_SPP)

fuzz:
	FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_RUNS=$(FUZZ_RUNS) bash tests/fuzz/run.sh
