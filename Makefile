# The two commands of README.md. Both install what they need, then build.
BUILD ?= build
JOBS  ?= 2

.PHONY: deps build demo test bench clean
deps:
	packaging/install-deps

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3
	cmake --build $(BUILD) -j $(JOBS)

# The CLI grasp experiment and ladder first (always); then the FreeCAD addon is installed
# (a symlink in ~/.local/share/FreeCAD/Mod) and, with a display, FreeCAD opens the demo
# document (plugin/freecad/demo.py: the cylinder and the block, the task panel open).
FREECAD_MOD ?= $(HOME)/.local/share/FreeCAD/Mod
demo: build
	$(BUILD)/plugin/cli/hapticgrasp demo
	@if [ -e "$(FREECAD_MOD)/HapticGrasp" ] && [ ! -L "$(FREECAD_MOD)/HapticGrasp" ]; then \
	  echo "$(FREECAD_MOD)/HapticGrasp exists and is not a symlink: addon not installed"; \
	else \
	  mkdir -p "$(FREECAD_MOD)" && ln -sfn "$(abspath $(BUILD))/freecad/HapticGrasp" "$(FREECAD_MOD)/HapticGrasp" && \
	  echo "FreeCAD addon: $(FREECAD_MOD)/HapticGrasp -> $(abspath $(BUILD))/freecad/HapticGrasp"; \
	fi
	@if [ -n "$$DISPLAY" ] && command -v freecad >/dev/null 2>&1; then \
	  HG_RESOURCES_DIR="$(CURDIR)/resources" freecad "$(CURDIR)/plugin/freecad/demo.py"; \
	else \
	  echo "no DISPLAY (or no freecad): FreeCAD demo skipped"; \
	fi

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The full speed/accuracy ladder on every sample part (minutes; not part of `make test`).
bench: build
	for p in cylinder block loft plate; do $(BUILD)/plugin/cli/hapticgrasp bench penetration --part $$p; done

clean:
	rm -rf $(BUILD)
