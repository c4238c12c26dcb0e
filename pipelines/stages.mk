# The pipeline's stages, defined once (docs/design.md §1, §7): their variables, their parameter
# stamps and their command lines. animation.mk runs them on this machine, slurm.mk submits them
# to a Slurm cluster; both include this file, so a stage runs the same command either way.
#
#   scene.gltf ─► rad-global ────► global.rlh ──────┐
#        └──────► rad-intervals ─► intervals.rti ─► rad-movies ─► movies/ ─► rad-compose ─► frames/ ─► movie.mp4

PIPELINES := $(dir $(lastword $(MAKEFILE_LIST)))
# The repository, and the defaults in it: relative when make runs in the repository's root (as
# the README does), absolute from anywhere else.
REPOSITORY := $(abspath $(PIPELINES)..)
in-repository = $(if $(filter $(CURDIR),$(REPOSITORY)),$(1),$(REPOSITORY)/$(1))

SCENE ?= $(call in-repository,pipelines/scenes/cornell-moving.gltf)
OUT   ?= out/$(basename $(notdir $(SCENE)))
BIN   ?= $(call in-repository,build/bin)

# FRAMES empty: the scene's animation, frames 0 to ceil(end x FPS) - 1, as the tools take it
# without --frames (rad-inspect --default-frames says which).
FRAMES  ?=
FPS     ?= 24
SIZE    ?= 352x240
# The stages' quality preset (--preset: draft, default or final; docs/design.md §1). rad-global,
# rad-intervals (final: 5 x 5 samples a pixel), rad-movies and rad-compose (final: every edge
# cell weighed by coverage) have quality knobs, so their command lines take it.
QUALITY ?= default

# The pixel filter of the frames (docs/design.md §6.4): none, box, gaussian or blackman-harris;
# empty: the tools' default, blackman-harris 1.5 px on 3 x 3 samples a pixel, as Blender's. It
# is rad-intervals' parameter (its item buffers decide the movies' coverage of those samples);
# rad-compose reads it from intervals.rti, so the two cannot disagree. none: one sample through
# each pixel centre, the frames before anti-aliasing.
PIXEL_FILTER ?=

GLOBAL_FLAGS    ?=
INTERVALS_FLAGS ?=
MOVIES_FLAGS    ?=
COMPOSE_FLAGS   ?=

# The calling Makefile's name, for its messages.
MAKEFILE_NAME := $(notdir $(firstword $(MAKEFILE_LIST)))
ifneq ($(filter-out none box gaussian blackman-harris,$(PIXEL_FILTER)),)
$(error $(MAKEFILE_NAME): PIXEL_FILTER=$(PIXEL_FILTER): expected none, box, gaussian or blackman-harris)
endif
# $(1) as one shell word, whatever it holds.
quote = '$(subst ','\'',$(1))'

# The variables are checked before anything runs or is written (check-variables.sh says what
# it allows and why): a path Make or a shell would split or read as syntax, and an OUT that a
# run or `make clean` could harm (the root, the home folder, the repository), stop the run here
# with one line.
VARIABLES_PROBLEM := $(shell $(PIPELINES)check-variables.sh $(call quote,$(REPOSITORY)) \
  $(call quote,$(SCENE)) $(call quote,$(OUT)) $(call quote,$(BIN)) $(call quote,$(FRAMES)) \
  $(call quote,$(SIZE)) $(call quote,$(FPS)) $(call quote,$(QUALITY)))
ifneq ($(VARIABLES_PROBLEM),)
$(error $(MAKEFILE_NAME): $(VARIABLES_PROBLEM))
endif
# A path that starts with `-` would read as an option to the tools.
dash-safe = $(if $(filter -%,$(1)),./$(1),$(1))
override SCENE := $(call dash-safe,$(SCENE))
override OUT   := $(call dash-safe,$(OUT))
override BIN   := $(call dash-safe,$(BIN))

ifeq ($(FRAMES),)
ifneq ($(filter-out clean,$(or $(MAKECMDGOALS),all)),)
ifeq ($(wildcard $(BIN)/rad-inspect),)
$(error $(MAKEFILE_NAME): $(BIN)/rad-inspect is not built; run pipelines/bootstrap.sh first)
endif
override FRAMES := $(shell $(BIN)/rad-inspect --default-frames $(SCENE) --fps $(FPS) 2>&1)
ifneq ($(.SHELLSTATUS),0)
$(error $(FRAMES))
endif
endif
endif
PRESET_ARG = $(if $(filter-out default,$(QUALITY)),--preset $(QUALITY))

GLOBAL_ARGS    = --frames $(FRAMES) --fps $(FPS) $(PRESET_ARG) $(GLOBAL_FLAGS)
INTERVALS_ARGS = --frames $(FRAMES) --fps $(FPS) --size $(SIZE) $(PRESET_ARG) \
                 $(if $(PIXEL_FILTER),--pixel-filter $(PIXEL_FILTER)) $(INTERVALS_FLAGS)
MOVIES_ARGS    = $(PRESET_ARG) $(MOVIES_FLAGS)
COMPOSE_ARGS   = --frames $(FRAMES) $(PRESET_ARG) $(COMPOSE_FLAGS)

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
# rad-intervals' item buffers of the frames $(1) (FIRST-LAST) counted into window file $(2), and
# the pass over the window files $(1), which writes what INTERVALS_CMD writes, byte for byte (it
# is INTERVALS_CMD plus --merge, which the provenance leaves out).
INTERVALS_WINDOW_CMD = $(strip $(BIN)/rad-intervals $(SCENE) -o $(2) $(INTERVALS_ARGS)) --window $(1)
INTERVALS_MERGE_CMD  = $(INTERVALS_CMD) --merge $(1)
MOVIES_SHARD_CMD  = $(call MOVIES_RUN,$(OUT)/movies-report-$(1)of$(2).json) --shard $(1)/$(2)
# The merge of the movie pieces of at most $(1) keys the shards baked (--piece-keys), of the
# movies of shard $(2) (i/n): it writes what MOVIES_CMD writes, byte for byte (it is MOVIES_CMD
# plus --merge-pieces and --shard, which the movies' provenance leaves out).
MOVIES_MERGE_CMD  = $(MOVIES_CMD) --merge-pieces $(1) --shard $(2)
# The same inside the task that baked movie shard $(2)'s pieces, after them: only the movies of
# which it baked a piece and whose pieces are all written (slurm.mk; movie_pieces.h).
MOVIES_MERGE_READY_CMD = $(call MOVIES_MERGE_CMD,$(1),$(2)) --merge-ready
COMPOSE_CHUNK_CMD = $(call COMPOSE_RUN,--frames $(1) $(COMPOSE_FLAGS),$(OUT)/compose-report-$(1).json)
GLOBAL_RUN  = $(strip $(BIN)/rad-global $(SCENE) -o $(1) $(GLOBAL_ARGS) --report $(2))
MOVIES_RUN  = $(strip $(BIN)/rad-movies $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti -o $(OUT)/movies \
                $(MOVIES_ARGS) --report $(1))
COMPOSE_RUN = $(strip $(BIN)/rad-compose $(SCENE) $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies \
                -o $(OUT)/frames $(1) --report $(2))
# The mp4 and the contact sheet (encode.sh: exactly the frames FRAMES names, odd sizes padded).
MP4_CMD     = $(PIPELINES)encode.sh mp4 $(OUT)/frames $(FRAMES) $(FPS) $(OUT)/movie.mp4
CONTACT_CMD = $(PIPELINES)encode.sh contact $(OUT)/frames $(FRAMES) $(FPS) $(OUT)/contact-sheet.png

# The stamps, one file each, OUT/NAME.params: a stage's parameters, and for `scene` the content
# hash of every file the scene is made of (rad-inspect --inputs: the glTF, its buffers and
# images). The stages depend on their stamps, not on the scene's file times, so Make re-runs
# exactly the stages a change of content or parameters affects (an older scene copied over, a
# moved vertex in a .bin, a recoloured texture included). The stamps are compared while the
# Makefile is read, and nothing is written then: a stamp that differs is made to depend on FORCE,
# so its rule writes it before the stages run, `make -n` lists the stages the change affects
# and writes nothing, and a stamp that cannot be written fails the run with one line.
STAMP_global    = $(GLOBAL_ARGS)
STAMP_intervals = $(INTERVALS_ARGS)
STAMP_movies    = $(MOVIES_ARGS)
STAMP_compose   = $(COMPOSE_ARGS)
STAMPS := scene global intervals movies compose
same-text     = $(and $(findstring x$(1)x,x$(2)x),$(findstring x$(2)x,x$(1)x))
stamp-differs = $(if $(call same-text,$(file <$(OUT)/$(1).params),$(STAMP_$(1))),,differs)

# Only the goals that run stages read the scene (clean and stage-commands need no built tools).
ifneq ($(filter-out clean stage-commands,$(or $(MAKECMDGOALS),all)),)
ifeq ($(wildcard $(BIN)/rad-inspect),)
$(error $(MAKEFILE_NAME): $(BIN)/rad-inspect is not built; run pipelines/bootstrap.sh first)
endif
STAMP_scene := $(shell $(BIN)/rad-inspect --inputs $(SCENE) 2>&1)
ifneq ($(.SHELLSTATUS),0)
$(error $(STAMP_scene))
endif
$(foreach s,$(STAMPS),$(if $(call stamp-differs,$(s)),$(eval $(OUT)/$(s).params: FORCE)))
endif

# Writes stamp $(1) (scene, global, ...) as the recipe of $(OUT)/$(1).params.
write-stamp = @err=$$( { mkdir -p $(@D) && printf '%s\n' $(call quote,$(STAMP_$(1))) > $@.tmp.$$$$ && \
	  mv -f $@.tmp.$$$$ $@; } 2>&1 ) || { rm -f $@.tmp.$$$$ 2>/dev/null; \
	  echo "$(MAKEFILE_NAME): $@: cannot write the stamp: $${err\#\#*: }" >&2; exit 1; }

$(OUT)/%.params:
	$(call write-stamp,$*)

# The pre-flight check (docs/design.md §7): the scene's stamp is written only once the scene has
# a camera and something that emits (rad-inspect --preflight, which reads the file and solves
# nothing), and every stage depends on that stamp. So a default Blender export (no camera, no
# lamps) fails before the first stage with one line saying what to export, not after rad-global's
# solve. It runs whenever the scene's content changes; a scene that fails leaves the stamp as it
# was, so the next run checks again.
$(OUT)/scene.params:
	@$(BIN)/rad-inspect --preflight $(SCENE) >/dev/null
	$(call write-stamp,scene)

.PHONY: FORCE
FORCE:

# A stage binary that is not built is an error, not a stage quietly left out.
$(BIN)/rad-%:
	@echo "$(MAKEFILE_NAME): $@ is not built; run pipelines/bootstrap.sh first" >&2; exit 1

# What the toolchain sees in the scene (patches, emitters, dynamic nodes, camera, time range).
$(OUT)/scene.json: $(OUT)/scene.params $(BIN)/rad-inspect
	$(BIN)/rad-inspect --json $(SCENE) > $@.tmp.$$$$ && mv -f $@.tmp.$$$$ $@ || { rm -f $@.tmp.$$$$; exit 1; }

# Only what the pipeline wrote, by name (clean.sh); OUT was checked above.
clean:
	@$(PIPELINES)clean.sh $(OUT)

# $(info) prints the text as Make expanded it, with no shell in between to eat quotes.
stage-commands:
	$(info global	$(GLOBAL_CMD))
	$(info intervals	$(INTERVALS_CMD))
	$(info movies	$(MOVIES_CMD))
	$(info compose	$(COMPOSE_CMD))
	@:
