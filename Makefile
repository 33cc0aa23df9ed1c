# DUKW-Ling onboard stack. `make run` runs the main job, `make test` every test;
# both set everything up first (scripts/setup.sh is idempotent and fast when done).
.PHONY: setup run test bench lint clean

setup:
	@bash scripts/setup.sh

run: setup
	@bash scripts/run.sh $(ARGS)

test: setup
	@bash scripts/test.sh $(ARGS)

bench: setup
	@bash scripts/bench.sh $(ARGS)

lint: setup
	@bash -c 'source scripts/env.sh && ruff check src tests'

clean:
	rm -rf build install log .colcon-build.txt
