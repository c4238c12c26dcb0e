# The production pipeline on this machine (docs/design.md §1, §7):
#
#   make -f pipelines/animation.mk [SCENE=...] [FRAMES=0-95] [SIZE=352x240] [GLOBAL_FLAGS=...] ...
#
# The stages, their variables and command lines are in stages.mk (slurm.mk submits the same
# ones to a Slurm cluster).
# Each stage's parameters are kept in a stamp (OUT/STAGE.params), and the content hashes of the
# scene's files (the glTF, its buffers and images) in OUT/scene.params; a stamp is rewritten only
# when it changes, so Make re-runs exactly the stages a change affects: a new scene, buffer or
# texture content re-runs all; GLOBAL_FLAGS re-runs global → movies → compose; INTERVALS_FLAGS
# re-runs intervals → movies → compose; MOVIES_FLAGS re-runs movies → compose; COMPOSE_FLAGS
# re-runs compose only. `make -n` writes nothing.
# Every tool writes atomically, and directory outputs are marked done by a stamp written
# after the tool succeeded, so a killed stage leaves nothing Make would take as up to date.
# `make -j` is safe: global and intervals run side by side. `make clean` removes only the files
# the pipeline writes, by name (clean.sh). OUT, SCENE and BIN are checked before anything runs
# (check-variables.sh).

include $(dir $(lastword $(MAKEFILE_LIST)))stages.mk
.DEFAULT_GOAL := all

.PHONY: all frames clean stage-commands
.DELETE_ON_ERROR:

all: $(OUT)/movie.mp4 $(OUT)/contact-sheet.png
	@echo "animation.mk: frames in $(OUT)/frames, $(OUT)/movie.mp4, $(OUT)/contact-sheet.png" >&2

frames: $(OUT)/frames/.done

$(OUT)/global.rlh: $(OUT)/scene.params $(OUT)/global.params $(BIN)/rad-global
	$(GLOBAL_CMD)

$(OUT)/intervals.rti: $(OUT)/scene.params $(OUT)/intervals.params $(BIN)/rad-intervals
	$(INTERVALS_CMD)

# The folder is emptied first (of the pipeline's own files, clean.sh): movies of an earlier run
# (another intervals.rti) must not linger. Two runs into one OUT take turns on the folders
# (flock): a folder is emptied and written under its exclusive lock and read under a shared one
# (rad-compose reads movies/, encode.sh frames/; the order movies before frames), so neither
# run empties what the other is reading. The tool is exec'd, so a signal to make reaches it.
$(OUT)/movies/.done: $(OUT)/scene.params $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies.params $(BIN)/rad-movies
	exec 8>$(OUT)/.movies.lock && flock 8 && $(PIPELINES)clean.sh $(OUT) movies && exec $(MOVIES_CMD)
	@touch $@

$(OUT)/frames/.done: $(OUT)/scene.params $(OUT)/global.rlh $(OUT)/intervals.rti $(OUT)/movies/.done $(OUT)/compose.params \
                     $(BIN)/rad-compose
	exec 8>$(OUT)/.movies.lock 9>$(OUT)/.frames.lock && flock -s 8 && flock 9 && \
	  $(PIPELINES)clean.sh $(OUT) frames && exec $(COMPOSE_CMD)
	@touch $@

$(OUT)/movie.mp4: $(OUT)/frames/.done
	$(MP4_CMD)

$(OUT)/contact-sheet.png: $(OUT)/frames/.done
	$(CONTACT_CMD)
