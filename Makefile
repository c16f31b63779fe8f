# The two commands of README.md. Both install what they need, then build.
BUILD ?= build
JOBS  ?= 2

.PHONY: deps build demo test bench clean
deps:
	packaging/install-deps

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(BUILD)/plugin/cli/hapticgrasp demo

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The full speed/accuracy ladder on every sample part (minutes; not part of `make test`).
bench: build
	for p in cylinder block loft plate; do $(BUILD)/plugin/cli/hapticgrasp bench penetration --part $$p; done

clean:
	rm -rf $(BUILD)
