# The production pipeline (DESIGN.md §1, §7): make -f pipelines/animation.mk [VAR=value ...]
#
#   scene.gltf ─► rad-global ─► global.rlh ──┐
#        └──────► rad-intervals ─► intervals.rti ─► rad-movies ─► movies/ ─► rad-compose ─► frames/ ─► movie.mp4
#
# Stages whose tools are not built yet are reported, not faked.

SCENE ?= pipelines/scenes/cornell-moving.gltf
OUT   ?= out/$(basename $(notdir $(SCENE)))
BIN   ?= build/bin

.PHONY: all clean
.DELETE_ON_ERROR:

all: $(OUT)/scene.json
	@for t in rad-global rad-intervals rad-movies rad-compose; do \
	  test -x $(BIN)/$$t || echo "animation.mk: $$t is not built yet; frames and movie.mp4 need it" >&2; \
	done

$(OUT):
	mkdir -p $@

# What the toolchain sees in the scene (patches, emitters, dynamic nodes, camera, time range).
$(OUT)/scene.json: $(SCENE) $(BIN)/rad-inspect | $(OUT)
	$(BIN)/rad-inspect --json $(SCENE) > $@.tmp && mv $@.tmp $@
	@$(BIN)/rad-inspect $(SCENE) >&2

clean:
	rm -rf $(OUT)
