# The pipeline's stages, defined once (DESIGN.md §1, §7): their variables, their parameter
# stamps and their command lines. animation.mk runs them on this machine, slurm.mk submits them
# to a Slurm cluster; both include this file, so a stage runs the same command either way.
#
#   scene.gltf ─► rad-global ────► global.rlh ──────┐
#        └──────► rad-intervals ─► intervals.rti ─► rad-movies ─► movies/ ─► rad-compose ─► frames/ ─► movie.mp4

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

FIRST_FRAME = $(firstword $(subst -, ,$(FRAMES)))

# The stage command lines, written once: the rules run them, `make -f animation.mk
# stage-commands` prints them (one `STAGE<TAB>command` line each) for bench.py and tradeoff.py,
# which time each stage themselves.
GLOBAL_CMD    = $(call GLOBAL_RUN,$(OUT)/global.rlh,$(OUT)/global-report.json)
INTERVALS_CMD = $(strip $(BIN)/rad-intervals $(SCENE) -o $(OUT)/intervals.rti $(INTERVALS_ARGS) \
                  --report $(OUT)/intervals-report.json)
MOVIES_CMD    = $(call MOVIES_RUN,$(OUT)/movies-report.json)
COMPOSE_CMD   = $(call COMPOSE_RUN,$(COMPOSE_ARGS),$(OUT)/compose-report.json)
# The farm's pieces of a stage (slurm.mk): rad-global's time window $(1) (FIRST-LAST) into
# window file $(2), and the merge of the window files $(1), which writes what GLOBAL_CMD writes,
# byte for byte (it is GLOBAL_CMD plus --merge); movie shard $(1) of $(2); the frames $(1).
GLOBAL_WINDOW_CMD = $(call GLOBAL_RUN,$(2),$(2:.rkw=-report.json)) --window $(1)
GLOBAL_MERGE_CMD  = $(GLOBAL_CMD) --merge $(1)
MOVIES_SHARD_CMD  = $(call MOVIES_RUN,$(OUT)/movies-report-$(1)of$(2).json) --shard $(1)/$(2)
COMPOSE_CHUNK_CMD = $(call COMPOSE_RUN,--frames $(1) $(COMPOSE_FLAGS),$(OUT)/compose-report-$(1).json)
GLOBAL_RUN  = $(strip $(BIN)/rad-global $(SCENE) -o $(1) $(GLOBAL_ARGS) --report $(2))
MOVIES_RUN  = $(strip $(BIN)/rad-movies $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti -o $(OUT)/movies \
                $(MOVIES_ARGS) --report $(1))
COMPOSE_RUN = $(strip $(BIN)/rad-compose $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies \
                -o $(OUT)/frames $(1) --report $(2))
# The mp4, and every 12th frame 4 across. Written to $@.tmp, then moved.
MP4_CMD     = ffmpeg -loglevel error -y -framerate $(FPS) -start_number $(FIRST_FRAME) \
                -i $(OUT)/frames/%04d.png -c:v libx264 -pix_fmt yuv420p -crf 18 -f mp4 $(OUT)/movie.mp4.tmp && \
              mv -f $(OUT)/movie.mp4.tmp $(OUT)/movie.mp4
CONTACT_CMD = ffmpeg -loglevel error -y -start_number $(FIRST_FRAME) -i $(OUT)/frames/%04d.png \
                -vf "select=not(mod(n\,12)),tile=4x2:padding=4:color=white" -frames:v 1 -update 1 -f image2 \
                $(OUT)/contact-sheet.png.tmp && mv -f $(OUT)/contact-sheet.png.tmp $(OUT)/contact-sheet.png

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

# A stage binary that is not built is an error, not a stage quietly left out.
$(BIN)/rad-%:
	@echo "$(notdir $(firstword $(MAKEFILE_LIST))): $@ is not built; run pipelines/bootstrap.sh first" >&2; exit 1

# What the toolchain sees in the scene (patches, emitters, dynamic nodes, camera, time range).
$(OUT)/scene.json: $(SCENE) $(BIN)/rad-inspect
	@mkdir -p $(@D)
	$(BIN)/rad-inspect --json $(SCENE) > $@.tmp && mv -f $@.tmp $@

clean:
	rm -rf $(OUT)

# $(info) prints the text as Make expanded it, with no shell in between to eat quotes.
stage-commands:
	$(info global	$(GLOBAL_CMD))
	$(info intervals	$(INTERVALS_CMD))
	$(info movies	$(MOVIES_CMD))
	$(info compose	$(COMPOSE_CMD))
	@:
