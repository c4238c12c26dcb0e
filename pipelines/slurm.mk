# The production pipeline on a Slurm cluster, used like animation.mk (issue 17):
#
#   make -f pipelines/slurm.mk [SCENE=...] [FRAMES=0-95] [SHARDS=4] [PARTITION=...] [WAIT=1] ...
#
# Same variables, stamps and stage command lines as animation.mk (stages.mk). Each stage that is
# not up to date is submitted with sbatch, in stage order, depending `afterok` on the jobs this
# run submitted for its inputs; a stage that is up to date is not submitted, so a re-run after a
# parameter change submits exactly what animation.mk would run:
#   rad-global and rad-intervals     one job each, side by side; with GLOBAL_WINDOWS=W, rad-global
#                                    as an array over W time windows of FRAMES (`--window`) and
#                                    their merge (`--merge`), whose global.rlh is the one job's,
#                                    byte for byte
#                                    With INTERVAL_WINDOWS=W (default 4), rad-intervals as an
#                                    array drawing the item buffers of W contiguous windows of
#                                    FRAMES (`--window`, each writing its frames' visible samples)
#                                    and the pass deciding the movies from them (`--merge`), whose
#                                    intervals.rti is the one job's, byte for byte
#                                    Each merge is run by the window task that ends last
#                                    (slurm-merge-ready.sh, under a lock), not by a job of its
#                                    own: no scheduling latency between the windows and it
#   rad-movies                       an array over `--shard i/SHARDS`; with MOVIE_PIECE_KEYS=K
#                                    (the default), a movie of more than K keys is baked as
#                                    pieces of at most K keys spread over the shards
#                                    (`--piece-keys`), and each task then joins the movies whose
#                                    last piece it wrote (`--merge-pieces K --merge-ready`, under
#                                    a lock per movie) into the movies one task bakes, byte for
#                                    byte: no merge stage
#   rad-compose                      an array over SHARDS contiguous chunks of FRAMES, each
#                                    also encoding its frames as a segment of the mp4
#   the mp4 and the contact sheet    one job each; the mp4 joins the segments (-c copy,
#                                    encode.sh concat), so no task encodes every frame
# Every task logs to OUT/logs/STAGE_TASK.log. A split stage's pieces stamp themselves
# (OUT/movies/.shard-I-of-N, OUT/frames/.chunk-I-of-N) and its done-stamp is written by a job
# that runs only when every piece succeeded, so a re-run after a failure or a killed task
# resubmits only the missing pieces. A failed task cancels the jobs that depend on it
# (--kill-on-invalid-dep). WAIT=1 blocks until this run's jobs have left the queue and exits
# non-zero with one line naming the first failed stage, task and log.
#
# PARTITION (default: the cluster's default one) and SBATCH_FLAGS (e.g. --account=...,
# --time=..., --mem=...) go to every sbatch. OUT must be on a file system every node sees.

HERE := $(dir $(lastword $(MAKEFILE_LIST)))
include $(HERE)stages.mk
.DEFAULT_GOAL := all

SHARDS         ?= 4
GLOBAL_WINDOWS ?= 1
# rad-intervals' windows of item buffers (1: one job). Its sequential pass over their counts is
# a small part of its time (docs/results.md, "rad-intervals' item buffers by windows").
INTERVAL_WINDOWS ?= 4
# Keys per movie piece (rad-movies --piece-keys; 0: whole movies, no merge). Each piece plans
# its movie again, so a smaller piece cuts the longest task and adds planning (docs/results.md,
# "Farm tasks finer than one movie" and its sequel).
MOVIE_PIECE_KEYS ?= 4
# The cut by known cost (rad-movies --piece-costs, tools/stages/movie_cut.h): the movies reports
# of an earlier run of these movies (e.g. OUT/movies-report-*.json, the shards' reports of the
# run before); a movie that took more than MOVIE_PIECE_SECONDS is cut into pieces of about that
# cost, the others baked whole (movies the reports do not name: MOVIE_PIECE_KEYS), every unit
# dealt to the shards longest first. The reports are copied to OUT/piece-costs/ under their
# content's checksum before the tasks are submitted (this run rewrites the shards' reports), and
# the shards' stamps name it, so pieces of another cut are never merged. Empty: by keys.
MOVIE_PIECE_COSTS   ?=
MOVIE_PIECE_SECONDS ?= 2
PARTITION    ?=
WAIT         ?= 0
SBATCH_FLAGS ?=

LOGS = $(OUT)/logs
comma := ,
space := $(subst ,, )
# The mp4's segment of the frames $(1) (FIRST-LAST), encoded by the compose task that made them.
SEGMENT_CMD = $(PIPELINES)encode.sh segment $(OUT)/frames $(1) $(FPS) $(OUT)/frames/segment-$(1).mp4
JOBS = $(OUT)/slurm-jobs

# This run's submissions (STAGE JOBID TASKS per line): dependencies and WAIT=1 read them.
ifeq ($(filter clean stage-commands,$(MAKECMDGOALS))$(findstring n,$(firstword -$(MAKEFLAGS))),)
$(shell mkdir -p $(OUT) && rm -f $(JOBS))
endif

ifneq ($(words $(subst -, ,$(FRAMES))) $(findstring x,$(FRAMES)),2 )
$(error slurm.mk: FRAMES=$(FRAMES): give FIRST-LAST (a step is not split into chunks))
endif
# FRAMES split into at most $(1) contiguous chunks, FIRST-LAST each.
split-frames = $(shell awk -v a=$(word 1,$(subst -, ,$(FRAMES))) -v b=$(word 2,$(subst -, ,$(FRAMES))) \
  -v n=$(1) 'BEGIN { c = b - a + 1; if (n > c) n = c; \
  for (i = 0; i < n; ++i) printf "%d-%d ", a + int(c * i / n), a + int(c * (i + 1) / n) - 1 }')
CHUNKS := $(call split-frames,$(SHARDS))
CHUNK_COUNT := $(words $(CHUNKS))
# rad-global's time windows, and the window files the merge joins. rad-global deals out the key
# times (`--print-windows`, the key grid of --frames and --key-step), so no window is without one
# however GLOBAL_WINDOWS and the key step meet; a plain split of the frames is not.
# `clean` and `stage-commands` need no windows, and so no built rad-global.
ifeq ($(GLOBAL_WINDOWS),1)
WINDOWS := $(FRAMES)
else ifneq ($(filter-out clean stage-commands,$(or $(MAKECMDGOALS),all)),)
WINDOWS := $(shell $(BIN)/rad-global $(SCENE) -o $(OUT)/global.rlh $(GLOBAL_ARGS) --print-windows $(GLOBAL_WINDOWS))
ifeq ($(strip $(WINDOWS)),)
$(error slurm.mk: GLOBAL_WINDOWS=$(GLOBAL_WINDOWS): $(BIN)/rad-global --print-windows gave no windows (build it first))
endif
endif
WINDOW_COUNT := $(words $(WINDOWS))
# rad-intervals' windows: contiguous chunks of FRAMES (any frame may start one).
INTERVAL_WINDOW_LIST  := $(call split-frames,$(INTERVAL_WINDOWS))
INTERVAL_WINDOW_COUNT := $(words $(INTERVAL_WINDOW_LIST))
INTERVAL_WINDOW_FILES := $(foreach i,$(shell seq 0 $$(($(INTERVAL_WINDOW_COUNT) - 1))),$(OUT)/interval-windows/w$(i).rvs)
WINDOW_FILES := $(foreach i,$(shell seq 0 $$(($(WINDOW_COUNT) - 1))),$(OUT)/global-windows/w$(i).rkw)

# In a window task of a split stage, after its window's stamp: the merge $(4) of the $(2) windows
# in folder $(1) into $(3), run when this task finds them all done (slurm-merge-ready.sh).
MERGE_READY = $(HERE)slurm-merge-ready.sh $(1) $(2) $(3) $(4)

# Submits stage $(1): array indices $(2) (a shell word; empty: one task, numbered 0), after the
# jobs this run submitted for the stages $(3), running the command $(4).
submit = mkdir -p $(LOGS) && \
  tasks=$(or $(2),0) && \
  for t in $$(echo $$tasks | tr , ' '); do rm -f $(LOGS)/$(1)_$$t.log $(LOGS)/$(1)_$$t.exit; done && \
  deps=$$(awk -v want=" $(3) " 'index(want, " " $$1 " ") {printf ":%s", $$2}' $(JOBS) 2>/dev/null || true) && \
  id=$$(sbatch --parsable --kill-on-invalid-dep=yes --job-name=rad-$(1) \
    $(if $(PARTITION),--partition=$(PARTITION)) $(SBATCH_FLAGS) $(if $(2),--array=$(2)) \
    $${deps:+--dependency=afterok$$deps} --output=$(LOGS)/$(1)_$(if $(2),%a,0).log \
    $(HERE)slurm-task.sh $(LOGS) $(1) $(call quote,$(4))) && \
  echo "$(1) $${id%%;*} $$tasks" >> $(JOBS) && \
  echo "slurm.mk: $(1) submitted: job $${id%%;*}, tasks $$tasks$${deps:+, after job$$(echo $$deps | tr : ' ')}" >&2

.PHONY: all frames clean stage-commands

all: $(OUT)/movie.mp4 $(OUT)/contact-sheet.png
ifeq ($(WAIT),1)
	@$(HERE)slurm-wait.sh $(JOBS) $(LOGS)
	@echo "slurm.mk: frames in $(OUT)/frames, $(OUT)/movie.mp4, $(OUT)/contact-sheet.png" >&2
else
	@echo "slurm.mk: submitted; logs in $(LOGS) (WAIT=1 blocks until the jobs end)" >&2
endif

frames: $(OUT)/frames/.done

# One job, or GLOBAL_WINDOWS time windows side by side and their merge (the same bytes), run by
# the window task that ends last (slurm-merge-ready.sh: no job, no scheduling latency for it);
# a merge job of its own only when every window is done and the merge is not.
$(OUT)/global.rlh: $(OUT)/scene.params $(OUT)/global.params $(BIN)/rad-global
ifeq ($(WINDOW_COUNT),1)
	@$(call submit,global,,,$(GLOBAL_CMD))
else
	@missing=$$($(HERE)slurm-pieces.sh $(OUT)/global-windows window $(WINDOW_COUNT) $(JOBS) "" $^) && \
	if [ -n "$$missing" ]; then \
	  $(call submit,global,$$missing,,set -- $(WINDOWS) && shift $${SLURM_ARRAY_TASK_ID} && \
	    $(call GLOBAL_WINDOW_CMD,$$1,$(OUT)/global-windows/w$${SLURM_ARRAY_TASK_ID}.rkw) && \
	    touch $(OUT)/global-windows/.window-$${SLURM_ARRAY_TASK_ID}-of-$(WINDOW_COUNT) && \
	    $(call MERGE_READY,$(OUT)/global-windows,$(WINDOW_COUNT),$@,$(call GLOBAL_MERGE_CMD,$(WINDOW_FILES)))); \
	else \
	  $(call submit,global-merge,,,$(call GLOBAL_MERGE_CMD,$(WINDOW_FILES))); \
	fi
endif

# One job, or INTERVAL_WINDOWS windows of item buffers side by side and the pass over their
# counts (the same bytes), run by the window task that ends last, as rad-global's merge.
$(OUT)/intervals.rti: $(OUT)/scene.params $(OUT)/intervals.params $(BIN)/rad-intervals
ifeq ($(INTERVAL_WINDOW_COUNT),1)
	@$(call submit,intervals,,,$(INTERVALS_CMD))
else
	@missing=$$($(HERE)slurm-pieces.sh $(OUT)/interval-windows window $(INTERVAL_WINDOW_COUNT) $(JOBS) "" $^) && \
	if [ -n "$$missing" ]; then \
	  $(call submit,intervals,$$missing,,set -- $(INTERVAL_WINDOW_LIST) && shift $${SLURM_ARRAY_TASK_ID} && \
	    $(call INTERVALS_WINDOW_CMD,$$1,$(OUT)/interval-windows/w$${SLURM_ARRAY_TASK_ID}.rvs) && \
	    touch $(OUT)/interval-windows/.window-$${SLURM_ARRAY_TASK_ID}-of-$(INTERVAL_WINDOW_COUNT) && \
	    $(call MERGE_READY,$(OUT)/interval-windows,$(INTERVAL_WINDOW_COUNT),$@,$(call INTERVALS_MERGE_CMD,$(INTERVAL_WINDOW_FILES)))); \
	else \
	  $(call submit,intervals-merge,,,$(call INTERVALS_MERGE_CMD,$(INTERVAL_WINDOW_FILES))); \
	fi
endif

# The shards' stamps name the piece size (.pshardK-I-of-N), so that pieces of another size are
# never merged: slurm-pieces.sh empties the folder when the stamps are of another kind.
ifneq ($(strip $(MOVIE_PIECE_COSTS)),)
MOVIES_COST_SUM   := $(firstword $(shell cat $(MOVIE_PIECE_COSTS) 2>/dev/null | cksum))
MOVIES_COST_FILES := $(foreach i,$(shell seq $(words $(MOVIE_PIECE_COSTS))),$(OUT)/piece-costs/$(MOVIES_COST_SUM)-$(i).json)
MOVIES_SHARD_KIND := pshard$(MOVIE_PIECE_KEYS)cost$(MOVIES_COST_SUM)
MOVIES_PIECE_ARGS := $(space)--piece-keys $(MOVIE_PIECE_KEYS)$(foreach f,$(MOVIES_COST_FILES), --piece-costs $(f)) \
                     --piece-seconds $(MOVIE_PIECE_SECONDS)
MOVIES_MERGE_K    := $(MOVIE_PIECE_KEYS)
ifeq ($(filter-out 0,$(MOVIE_PIECE_KEYS)),)
$(error slurm.mk: MOVIE_PIECE_COSTS needs MOVIE_PIECE_KEYS > 0, the cut of the movies the reports do not name)
endif
MOVIES_MERGE_COSTS = $(foreach f,$(MOVIES_COST_FILES), --piece-costs $(f)) --piece-seconds $(MOVIE_PIECE_SECONDS)
# The snapshot of the reports the tasks read (cp fails, and stops the run, on a missing one).
MOVIES_COST_COPY   = mkdir -p $(OUT)/piece-costs && set -- $(MOVIE_PIECE_COSTS) && \
                     for f in $(MOVIES_COST_FILES); do cp "$$1" "$$f" && shift || exit 1; done &&
else
MOVIES_SHARD_KIND := $(if $(filter-out 0,$(MOVIE_PIECE_KEYS)),pshard$(MOVIE_PIECE_KEYS),shard)
MOVIES_PIECE_ARGS := $(if $(filter-out 0,$(MOVIE_PIECE_KEYS)), --piece-keys $(MOVIE_PIECE_KEYS))
MOVIES_MERGE_K    := $(MOVIE_PIECE_KEYS)
endif

# The shards, each (with pieces) then joining the movies whose last piece it wrote, then a job
# that stamps. A shard's stamp follows its merges, so a task killed before or during them runs
# again and merges what it finds complete (a movie merged meanwhile has the pieces of the re-run
# removed).
MOVIES_TASK_MERGE = $(if $(MOVIES_PIECE_ARGS), && $(call MOVIES_MERGE_READY_CMD,$(MOVIES_MERGE_K),$${SLURM_ARRAY_TASK_ID}/$(SHARDS))$(MOVIES_MERGE_COSTS))
$(OUT)/movies/.done: $(OUT)/scene.params $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies.params $(BIN)/rad-movies
	@rm -f $@ && $(MOVIES_COST_COPY) \
	missing=$$($(HERE)slurm-pieces.sh $(OUT)/movies $(MOVIES_SHARD_KIND) $(SHARDS) $(JOBS) "global global-merge intervals intervals-merge" $^) && \
	if [ -n "$$missing" ]; then \
	  $(call submit,movies,$$missing,global global-merge intervals intervals-merge,$(call MOVIES_SHARD_CMD,$${SLURM_ARRAY_TASK_ID},$(SHARDS))$(MOVIES_PIECE_ARGS)$(MOVIES_TASK_MERGE) \
	    && touch $(OUT)/movies/.$(MOVIES_SHARD_KIND)-$$SLURM_ARRAY_TASK_ID-of-$(SHARDS)) && \
	  $(call submit,movies-done,,movies,touch $@); \
	else touch $@; fi

$(OUT)/frames/.done: $(OUT)/scene.params $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies/.done $(OUT)/compose.params \
                     $(BIN)/rad-compose
	@rm -f $@ && \
	missing=$$($(HERE)slurm-pieces.sh $(OUT)/frames chunk $(CHUNK_COUNT) $(JOBS) "global global-merge intervals intervals-merge movies" $^) && \
	if [ -n "$$missing" ]; then \
	  $(call submit,compose,$$missing,global global-merge intervals intervals-merge movies,set -- $(CHUNKS) && shift $$SLURM_ARRAY_TASK_ID && \
	    $(call COMPOSE_CHUNK_CMD,$$1) && $(call SEGMENT_CMD,$$1) && \
	    touch $(OUT)/frames/.chunk-$$SLURM_ARRAY_TASK_ID-of-$(CHUNK_COUNT)) && \
	  $(call submit,frames-done,,compose,touch $@); \
	else touch $@; fi

$(OUT)/movie.mp4: $(OUT)/frames/.done
	@$(call submit,mp4,,compose,$(PIPELINES)encode.sh concat $(OUT)/frames $(subst $(space),$(comma),$(strip $(CHUNKS))) $(FPS) $(OUT)/movie.mp4)

$(OUT)/contact-sheet.png: $(OUT)/frames/.done
	@$(call submit,contact-sheet,,compose,$(CONTACT_CMD))
