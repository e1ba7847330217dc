"""ShapeMove's language model: a T5 that reads shape + motion text and writes `[BETA]` followed by
motion tokens; the decoder state at `[BETA]` is projected to betas (``BetaHead``).

Loss = token cross-entropy + ``beta_weight`` * L1(betas). Saved with ``save_pretrained``
(safetensors) so plain ``transformers`` loads the language model; the beta head and ShapeMove's
metadata sit beside it in the same folder.
"""
from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path

import torch
from torch import nn

from ..errors import ShapeMoveError
from ..model_files import damaged_model_errors, verify_manifest, write_manifest
from .beta_head import BetaHead

FORMAT = "shapemove-t5/1"
T5_FILES = ("shapemove.json", "config.json", "model.safetensors", "beta_head.safetensors", "tokenizer.json")


@dataclass
class T5Size:
    """A small T5 for CPU training; ``base_model`` = a local pretrained folder overrides it."""
    d_model: int = 256
    d_ff: int = 1024
    num_layers: int = 4
    num_decoder_layers: int = 4
    num_heads: int = 4
    d_kv: int = 64
    dropout_rate: float = 0.1

    @classmethod
    def tiny(cls) -> "T5Size":
        return cls(d_model=64, d_ff=128, num_layers=1, num_decoder_layers=1, num_heads=2, d_kv=32, dropout_rate=0.0)


def shapemove_prompt(motion_text: str, shape_text: str | None = None) -> str:
    """The paper's input format: shape description, then the motion description."""
    motion_text = motion_text.strip().rstrip(".")
    head = (shape_text.strip().rstrip(".") + ". ") if shape_text and shape_text.strip() else ""
    return f"{head}The person demonstrates a motion like: {motion_text}."


class ShapeMoveT5(nn.Module):
    def __init__(self, lm, beta_head: BetaHead, vocab, beta_weight: float = 1.0):
        super().__init__()
        self.lm = lm
        self.beta_head = beta_head
        self.vocab = vocab  # tokenizer.MotionVocab
        self.beta_weight = beta_weight

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def build(cls, tokenizer, size: T5Size | None = None, base_model: Path | None = None, beta_weight: float = 1.0):
        from transformers import T5Config, T5ForConditionalGeneration

        from .tokenizer import MotionVocab

        vocab = MotionVocab(tokenizer)
        if base_model is not None:
            base_model = Path(base_model)
            if not (base_model / "config.json").is_file():
                raise ShapeMoveError(f"{base_model} is not a pretrained T5 folder (no config.json)")
            lm = T5ForConditionalGeneration.from_pretrained(str(base_model), local_files_only=True)
        else:
            size = size or T5Size()
            cfg = T5Config(vocab_size=len(tokenizer), d_model=size.d_model, d_ff=size.d_ff, d_kv=size.d_kv,
                           num_layers=size.num_layers, num_decoder_layers=size.num_decoder_layers,
                           num_heads=size.num_heads, dropout_rate=size.dropout_rate,
                           pad_token_id=tokenizer.pad_token_id, eos_token_id=tokenizer.eos_token_id,
                           decoder_start_token_id=tokenizer.pad_token_id, tie_word_embeddings=False)
            lm = T5ForConditionalGeneration(cfg)
        lm.resize_token_embeddings(len(tokenizer))
        return cls(lm, BetaHead(lm.config.d_model), vocab, beta_weight)

    # -- training -----------------------------------------------------------------------------
    def forward(self, input_ids, attention_mask, labels, betas=None):
        """labels (B,L): [BETA] [SOM] codes [EOM] </s>, padded with -100 (text targets for the
        motion-to-text task have no [BETA]). Returns dict(loss, ce, l1, betas_pred)."""
        out = self.lm(input_ids=input_ids, attention_mask=attention_mask, labels=labels, output_hidden_states=True)
        ce = out.loss
        # decoder input is labels shifted right: position i+1 has labels[i] as input, so the state
        # whose INPUT is [BETA] sits one step after [BETA]'s position in labels
        hidden = out.decoder_hidden_states[-1]
        is_beta = labels == self.vocab.beta_id
        has_beta = is_beta.any(1)
        l1 = ce.new_zeros(())
        pred = None
        if has_beta.any():
            pos = is_beta.float().argmax(1) + 1
            pos = pos.clamp(max=hidden.shape[1] - 1)
            h = hidden[torch.arange(hidden.shape[0]), pos][has_beta]
            pred = self.beta_head(h)
            if betas is not None:
                l1 = (pred - betas[has_beta]).abs().mean()
        return {"loss": ce + self.beta_weight * l1, "ce": ce.detach(), "l1": l1.detach(), "betas_pred": pred}

    # -- persistence --------------------------------------------------------------------------
    def save(self, directory: Path, tokenizer, meta: dict | None = None) -> None:
        """Atomic: written into ``directory.tmp`` then renamed over ``directory``."""
        import shutil

        from safetensors.torch import save_file

        directory = Path(directory)
        tmp = directory.with_name(directory.name + ".tmp")
        shutil.rmtree(tmp, ignore_errors=True)
        self.lm.save_pretrained(str(tmp), safe_serialization=True)
        tokenizer.save_pretrained(str(tmp))
        save_file({k: v.contiguous() for k, v in self.beta_head.state_dict().items()}, str(tmp / "beta_head.safetensors"))
        info = {"format": FORMAT, "beta_weight": self.beta_weight, "d_model": self.lm.config.d_model, **(meta or {})}
        (tmp / "shapemove.json").write_text(json.dumps(info, indent=2, default=str))
        write_manifest(tmp)  # sha256 of every file: loading refuses a damaged or swapped file
        old = directory.with_name(directory.name + ".old")
        shutil.rmtree(old, ignore_errors=True)
        if directory.exists():
            os.replace(directory, old)
        os.replace(tmp, directory)
        shutil.rmtree(old, ignore_errors=True)

    @classmethod
    def load(cls, directory: Path):
        from safetensors.torch import load_file
        from transformers import T5ForConditionalGeneration

        from .tokenizer import MotionVocab, load_tokenizer

        directory = Path(directory)
        info_file = directory / "shapemove.json"
        if not info_file.is_file():
            raise ShapeMoveError(f"{directory} is not a ShapeMove T5 model (no shapemove.json)")
        verify_manifest(directory, required=T5_FILES)
        with damaged_model_errors(directory):
            info = json.loads(info_file.read_text())
            if not isinstance(info, dict) or info.get("format") != FORMAT:
                raise ShapeMoveError(f"{directory}: unsupported model format "
                                     f"{info.get('format') if isinstance(info, dict) else info!r} (expected {FORMAT})")
            tok = load_tokenizer(directory)
            lm = T5ForConditionalGeneration.from_pretrained(str(directory), local_files_only=True, dtype=torch.float32)
            head = BetaHead(lm.config.d_model)
            head.load_state_dict({k: v.float() for k, v in load_file(str(directory / "beta_head.safetensors")).items()})
            model = cls(lm, head, MotionVocab(tok), info.get("beta_weight", 1.0))
        model.info = info
        return model.eval(), tok


def size_from_dict(d: dict) -> T5Size:
    return T5Size(**{k: v for k, v in d.items() if k in asdict(T5Size())})
