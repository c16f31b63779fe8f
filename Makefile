# The two commands of README.md. Both install what they need, then build.
BUILD ?= build
JOBS  ?= 2

.PHONY: deps build demo test sanitize bench package fuzz clean
deps:
	packaging/install-deps

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3
	cmake --build $(BUILD) -j $(JOBS)

# The CLI grasp experiment and ladder first (always); then the FreeCAD addon is installed
# (a symlink in ~/.local/share/FreeCAD/Mod) and, with a display, FreeCAD opens the demo
# document (plugin/freecad/demo.py: the cylinder and the block, the task panel open), as
# root or as a normal user (packaging/demo-freecad). HG_DEMO_EXIT=1 closes it once set up.
demo: build
	$(BUILD)/plugin/cli/hapticgrasp demo
	packaging/demo-freecad $(BUILD) $(CURDIR)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan), then the
# threaded ones (label `threads`) under ThreadSanitizer (build-tsan); .ci/run runs this after
# `make test`. Suppressions and why: tests/sanitize/.
sanitize: deps
	tests/sanitize/run address build-asan $(JOBS)
	tests/sanitize/run thread build-tsan $(JOBS)

# The Debian package (CPack): build/packaging/hapticgrasp_<version>_<arch>.deb, then
# `sudo apt install ./build/packaging/hapticgrasp_*.deb` (README: Install).
package: build
	cmake --build $(BUILD) --target package

# The full speed/accuracy ladder on every sample part (minutes; not part of `make test`).
bench: build
	for p in cylinder block loft plate; do $(BUILD)/plugin/cli/hapticgrasp bench penetration --part $$p; done

# libFuzzer over every loader (README: Fuzzing): a clang build of its own, instrumented
# with ASan and UBSan (only what the targets need is built), then each target for
# FUZZ_SECONDS over a copy of its seeds (tests/fuzz/corpus), FUZZ_OPTIONS added to
# libFuzzer's (.ci/run: -seed=1). Not part of `make test`; CI runs it after.
FUZZ_BUILD   ?= build-fuzz
FUZZ_SECONDS ?= 30
FUZZ_OPTIONS ?=
fuzz: deps
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ -DHG_FUZZ=ON \
	  -DHG_FUZZ_SECONDS=$(FUZZ_SECONDS) -DPython_EXECUTABLE=/usr/bin/python3
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_targets
	cd $(FUZZ_BUILD) && FUZZ_OPTIONS="$(FUZZ_OPTIONS)" ctest -L fuzz --output-on-failure -j $(JOBS)

clean:
	rm -rf $(BUILD) $(FUZZ_BUILD)
