# The production pipeline (DESIGN.md §1, §7):
#
#   make -f pipelines/animation.mk [SCENE=...] [FRAMES=0-95] [SIZE=352x240] [GLOBAL_FLAGS=...] ...
#
#   scene.gltf ─► rad-global ────► global.rlh ──────┐
#        └──────► rad-intervals ─► intervals.rti ─► rad-movies ─► movies/ ─► rad-compose ─► frames/ ─► movie.mp4
#
# Each stage's parameters are written to a stamp file (OUT/*.params) that changes only when
# they change, so Make re-runs exactly the stages a change affects: GLOBAL_FLAGS re-runs
# global → movies → compose; INTERVALS_FLAGS re-runs intervals → movies → compose;
# MOVIES_FLAGS re-runs movies → compose; COMPOSE_FLAGS re-runs compose only.
# Every tool writes atomically, and directory outputs are marked done by a stamp written
# after the tool succeeded, so a killed stage leaves nothing Make would take as up to date.
# `make -j` is safe: global and intervals run side by side.

SCENE ?= pipelines/scenes/cornell-moving.gltf
OUT   ?= out/$(basename $(notdir $(SCENE)))
BIN   ?= build/bin

FRAMES ?= 0-95
FPS    ?= 24
SIZE   ?= 352x240

GLOBAL_FLAGS    ?=
INTERVALS_FLAGS ?=
MOVIES_FLAGS    ?=
COMPOSE_FLAGS   ?=

GLOBAL_ARGS    = --frames $(FRAMES) --fps $(FPS) $(GLOBAL_FLAGS)
INTERVALS_ARGS = --frames $(FRAMES) --fps $(FPS) --size $(SIZE) $(INTERVALS_FLAGS)
MOVIES_ARGS    = $(MOVIES_FLAGS)
COMPOSE_ARGS   = --frames $(FRAMES) $(COMPOSE_FLAGS)

# The stage command lines, written once: the rules below run them, `make -f animation.mk
# stage-commands` prints them (one `STAGE<TAB>command` line each) for bench.py and tradeoff.py,
# which time each stage themselves.
GLOBAL_CMD    = $(strip $(BIN)/rad-global $(SCENE) -o $(OUT)/global.rlh $(GLOBAL_ARGS) \
                  --report $(OUT)/global-report.json)
INTERVALS_CMD = $(strip $(BIN)/rad-intervals $(SCENE) -o $(OUT)/intervals.rti $(INTERVALS_ARGS) \
                  --report $(OUT)/intervals-report.json)
MOVIES_CMD    = $(strip $(BIN)/rad-movies $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti -o $(OUT)/movies \
                  $(MOVIES_ARGS) --report $(OUT)/movies-report.json)
COMPOSE_CMD   = $(strip $(BIN)/rad-compose $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies \
                  -o $(OUT)/frames $(COMPOSE_ARGS) --report $(OUT)/compose-report.json)

.PHONY: all frames clean stage-commands
.DELETE_ON_ERROR:

all: $(OUT)/movie.mp4 $(OUT)/contact-sheet.png
	@echo "animation.mk: frames in $(OUT)/frames, $(OUT)/movie.mp4, $(OUT)/contact-sheet.png" >&2

# A stage binary that is not built is an error, not a stage quietly left out.
$(BIN)/rad-%:
	@echo "animation.mk: $@ is not built; run pipelines/bootstrap.sh first" >&2; exit 1

frames: $(OUT)/frames/.done

# A stamp's content is the stage's parameters; it is rewritten only when they change. It is
# updated while the Makefile is read (not by a rule), so `make -n` already knows which stages
# a change of parameters affects.
update-params = $(shell mkdir -p $(OUT) && printf '%s\n' '$(2)' > $(OUT)/$(1).params.new && \
  { cmp -s $(OUT)/$(1).params.new $(OUT)/$(1).params && rm -f $(OUT)/$(1).params.new || \
    mv -f $(OUT)/$(1).params.new $(OUT)/$(1).params; })
ifeq ($(filter clean stage-commands,$(MAKECMDGOALS)),)
$(call update-params,global,$(GLOBAL_ARGS))
$(call update-params,intervals,$(INTERVALS_ARGS))
$(call update-params,movies,$(MOVIES_ARGS))
$(call update-params,compose,$(COMPOSE_ARGS))
endif

# What the toolchain sees in the scene (patches, emitters, dynamic nodes, camera, time range).
$(OUT)/scene.json: $(SCENE) $(BIN)/rad-inspect
	@mkdir -p $(@D)
	$(BIN)/rad-inspect --json $(SCENE) > $@.tmp && mv -f $@.tmp $@

$(OUT)/global.rlh: $(SCENE) $(OUT)/global.params $(BIN)/rad-global
	$(GLOBAL_CMD)

$(OUT)/intervals.rti: $(SCENE) $(OUT)/intervals.params $(BIN)/rad-intervals
	$(INTERVALS_CMD)

# The folder is emptied first: movies of an earlier run (another intervals.rti) must not linger.
$(OUT)/movies/.done: $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies.params $(BIN)/rad-movies
	@rm -rf $(OUT)/movies
	$(MOVIES_CMD)
	@touch $@

$(OUT)/frames/.done: $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies/.done $(OUT)/compose.params \
                     $(BIN)/rad-compose
	@rm -rf $(OUT)/frames
	$(COMPOSE_CMD)
	@touch $@

$(OUT)/movie.mp4: $(OUT)/frames/.done
	ffmpeg -loglevel error -y -framerate $(FPS) -start_number $(firstword $(subst -, ,$(FRAMES))) \
	  -i $(OUT)/frames/%04d.png -c:v libx264 -pix_fmt yuv420p -crf 18 -f mp4 $@.tmp
	mv -f $@.tmp $@

# Every 12th frame, 4 across.
$(OUT)/contact-sheet.png: $(OUT)/frames/.done
	ffmpeg -loglevel error -y -start_number $(firstword $(subst -, ,$(FRAMES))) -i $(OUT)/frames/%04d.png \
	  -vf "select=not(mod(n\,12)),tile=4x2:padding=4:color=white" -frames:v 1 -update 1 -f image2 $@.tmp
	mv -f $@.tmp $@

clean:
	rm -rf $(OUT)

# $(info) prints the text as Make expanded it, with no shell in between to eat quotes.
stage-commands:
	$(info global	$(GLOBAL_CMD))
	$(info intervals	$(INTERVALS_CMD))
	$(info movies	$(MOVIES_CMD))
	$(info compose	$(COMPOSE_CMD))
	@:

