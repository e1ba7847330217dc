"""ShapeMove's language model: reads shape + motion text, writes `[BETA]` followed by motion
tokens; the decoder state at `[BETA]` is projected to betas (``BetaHead``).

Two encoders (``encoder`` in the folder's ``shapemove.json``):
- ``"minilm"`` (default): the prompt is read by the frozen pretrained all-MiniLM-L6-v2
  (``text_encoder.py``). Shape text and motion text are encoded separately (segments 0 and 1),
  their token states projected 384 -> d_model and concatenated; a T5 *decoder* stack
  cross-attends to them and writes from its own motion-only vocabulary (pad, </s>, [BETA],
  [SOM], [EOM], the N FSQ codes). The stack is ``t5_decoder.T5Decoder`` (T5Stack's maths and
  parameter names in plain torch: loading never imports transformers). Saved as
  ``model.safetensors`` + ``config.json`` (the decoder's sizes) + the encoder's fingerprint,
  which loading checks.
- ``"t5"``: a whole T5 encoder-decoder on a sentencepiece tokenizer trained on the captions (from
  scratch), or a local pretrained T5 folder (``--base-model``) with its own tokenizer; saved with
  ``save_pretrained`` + ``tokenizer.json`` (its sha256 recorded and checked on load).
Format ``shapemove-t5/1`` folders (T5 + tokenizer, before the pretrained encoder) still load.

Loss = token cross-entropy + ``beta_weight`` * L1(betas). The beta head and ShapeMove's metadata
sit beside the weights in the same folder.
"""
from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path

import torch
import torch.nn.functional as F
from torch import nn

from ..errors import ShapeMoveError
from ..model_files import damaged_model_errors, sha256_file, verify_manifest, write_manifest
from .beta_head import BetaHead, build_head

FORMAT_V1 = "shapemove-t5/1"  # T5 + sentencepiece tokenizer (the default model until it is retrained)
FORMAT = "shapemove-t5/2"
ENCODERS = ("minilm", "t5")
T5_FILES = ("shapemove.json", "config.json", "model.safetensors", "beta_head.safetensors", "tokenizer.json")
MINILM_FILES = ("shapemove.json", "config.json", "model.safetensors", "beta_head.safetensors")
KNOWN_JSON, KNOWN_VECTORS = "known_texts.json", "known_texts.safetensors"
NULL_PROMPT = ""  # the motion text of unconditional examples (null_share) and of guidance's second pass


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
    sentence_token: bool = False   # MiniLM reader: add the pooled sentence vector as a memory slot
    text_dropout: float = 0.0      # MiniLM reader: share of training prompts read from that slot alone
    memory_k: int = 0              # MiniLM reader: retrieved clips read as memory (motion_memory.py); 0 = none
    memory_codes: int = 40         # tokens kept of each retrieved clip (40 = 8 s)
    memory_dropout: float = 0.0    # share of training prompts given no retrieved clips

    @classmethod
    def tiny(cls) -> "T5Size":
        return cls(d_model=64, d_ff=128, num_layers=1, num_decoder_layers=1, num_heads=2, d_kv=32, dropout_rate=0.0)


def shapemove_prompt(motion_text: str, shape_text: str | None = None) -> str:
    """The paper's input format: shape description, then the motion description."""
    motion_text = motion_text.strip().rstrip(".")
    head = (shape_text.strip().rstrip(".") + ". ") if shape_text and shape_text.strip() else ""
    return f"{head}The person demonstrates a motion like: {motion_text}."


class MiniLMDecoder(nn.Module):
    """MiniLM token states -> (projection + segment embedding) -> T5 decoder stack -> motion logits.
    The stack is ``t5_decoder.T5Decoder`` (T5Stack's maths and parameter names, no transformers)."""

    def __init__(self, config, text_dim: int = 384):
        super().__init__()
        from .t5_decoder import T5Decoder

        self.config = config
        d = config.d_model
        self.proj = nn.Sequential(nn.Linear(text_dim, d), nn.LayerNorm(d))
        self.segment = nn.Embedding(2, d)  # 0 shape text, 1 motion text
        if config.sentence_token:
            self.sentence_proj = nn.Sequential(nn.Linear(text_dim, d), nn.LayerNorm(d))
        self.decoder = T5Decoder(config)
        if getattr(config, "memory_k", 0):
            # retrieved clips' tokens: the decoder's own token embedding (so a code can be copied)
            # + position in the clip + rank of the clip + its caption's similarity to the prompt
            self.memory_pos = nn.Embedding(config.memory_codes, d)
            self.memory_rank = nn.Embedding(config.memory_k, d)
            self.memory_sim = nn.Linear(1, d)
            self.memory_norm = nn.LayerNorm(d)
        self.lm_head = nn.Linear(d, config.vocab_size, bias=False)

    @staticmethod
    def make_config(size: "T5Size", vocab_size: int):
        from .t5_decoder import T5DecoderConfig

        return T5DecoderConfig(vocab_size=vocab_size, d_model=size.d_model, d_ff=size.d_ff, d_kv=size.d_kv,
                               num_heads=size.num_heads, num_layers=size.num_decoder_layers,
                               dropout_rate=size.dropout_rate, sentence_token=size.sentence_token,
                               text_dropout=size.text_dropout, memory_k=size.memory_k,
                               memory_codes=size.memory_codes, memory_dropout=size.memory_dropout)

    def encode(self, states, mask, segments, memory_ids=None, memory_sims=None):
        """Memory (B, L', d) and its mask: the text (``encode_text``) followed, when the model reads
        retrieved clips, by their tokens (``memory_ids`` (B, k, C) vocab ids, -1 empty; ``memory_sims``
        (B, k) cosine similarity of each clip's caption to the prompt)."""
        enc, mask = self.encode_text(states, mask, segments)
        k = getattr(self.config, "memory_k", 0)
        if not k or memory_ids is None:
            return enc, mask
        B, kk, C = memory_ids.shape
        if kk != k or C > self.config.memory_codes:
            raise ShapeMoveError(f"retrieval memory of {kk} clips x {C} codes given; the model reads "
                                 f"{k} x {self.config.memory_codes}")
        present = memory_ids >= 0
        if self.training and self.config.memory_dropout > 0:
            drop = torch.rand(B, device=present.device) < self.config.memory_dropout
            present = present & ~drop[:, None, None]
        tok = self.decoder.embed_tokens(memory_ids.clamp(min=0))
        tok = tok + self.memory_pos.weight[:C][None, None] + self.memory_rank.weight[None, :, None]
        mem = self.memory_norm(tok) + self.memory_sim(memory_sims[..., None].to(tok))[:, :, None]
        return torch.cat([enc, mem.reshape(B, k * C, -1)], 1), torch.cat([mask, present.reshape(B, k * C)], 1)

    def encode_text(self, states, mask, segments):
        """Text memory (B, L', d) and its mask: the projected token states (+ segment embedding), led by
        the motion text's pooled sentence vector when ``config.sentence_token``. MiniLM was trained
        so that paraphrases have near sentence vectors; hiding the motion text's token states from a
        share (``text_dropout``) of training prompts makes the decoder read that vector, which
        carries over to wordings the captions never used."""
        enc = self.proj(states) + self.segment(segments)
        if not self.config.sentence_token:
            return enc, mask
        words = mask & (segments == 1)
        pooled = (states * words[..., None]).sum(1) / words.sum(1, keepdim=True).clamp(min=1)
        slot = self.sentence_proj(F.normalize(pooled, dim=-1))[:, None] + self.segment.weight[1]
        if self.training and self.config.text_dropout > 0:
            hide = torch.rand(len(mask), device=mask.device) < self.config.text_dropout
            mask = mask & ~(hide[:, None] & (segments == 1))
        return torch.cat([slot, enc], 1), torch.cat([torch.ones_like(mask[:, :1]), mask], 1)

    def step(self, enc, mask, decoder_ids, past=None, use_cache: bool = False):
        hidden, cache = self.decoder(decoder_ids, enc, mask, cache=past, use_cache=use_cache)
        return self.lm_head(hidden), hidden, cache


class ShapeMoveT5(nn.Module):
    def __init__(self, lm, beta_head: BetaHead, vocab, beta_weight: float = 1.0, encoder: str = "t5"):
        super().__init__()
        if encoder not in ENCODERS:
            raise ShapeMoveError(f"unknown text encoder {encoder!r}: expected one of {', '.join(ENCODERS)}")
        self.lm = lm
        self.beta_head = beta_head
        self.vocab = vocab  # tokenizer.MotionVocab
        self.beta_weight = beta_weight
        self.encoder_kind = encoder
        self.info: dict = {}
        self.memory = None  # motion_memory.MotionMemory the decoder reads, when it was trained with one
        self.memory_enabled = True  # False: the decoder reads no retrieved clips (to measure without)

    @property
    def memory_k(self) -> int:
        return int(getattr(self.lm.config, "memory_k", 0)) if self.encoder_kind == "minilm" else 0

    def memory_inputs(self, reader, motion_texts: list[str], exclude=None, rng=None) -> tuple:
        """(ids (B, k, C), sims (B, k)) of the clips retrieved for each motion text (none for the
        null prompt). ``exclude``: per text, clip families to leave out (training)."""
        if self.memory is None:
            raise ShapeMoveError("this model reads retrieved clips but has no motion memory "
                                 "(motion_memory.json/.safetensors missing from its folder)")
        return self.memory.lookup(reader, motion_texts, self.memory_k, self.lm.config.memory_codes,
                                  self.vocab.first_code_id, exclude, rng,
                                  empty=[t == NULL_PROMPT or not self.memory_enabled for t in motion_texts],
                                  codebook=self.vocab.num_codes)

    @property
    def d_model(self) -> int:
        return self.lm.config.d_model

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def build(cls, tokenizer, size: T5Size | None = None, base_model: Path | None = None, beta_weight: float = 1.0):
        """A whole T5 (encoder-decoder) on ``tokenizer``: from scratch, or a local pretrained folder."""
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
        return cls(lm, BetaHead(lm.config.d_model), vocab, beta_weight, "t5")

    @classmethod
    def build_minilm(cls, num_codes: int, size: T5Size | None = None, beta_weight: float = 1.0):
        """A T5 decoder on the frozen MiniLM's states, writing ``num_codes`` motion codes (the FSQ's
        codebook size)."""
        from .text_encoder import HIDDEN
        from .tokenizer import MotionVocab

        vocab = MotionVocab.motion_only(num_codes)
        lm = MiniLMDecoder(MiniLMDecoder.make_config(size or T5Size(), vocab.vocab_size), HIDDEN)
        return cls(lm, BetaHead(lm.config.d_model), vocab, beta_weight, "minilm")

    # -- inputs ---------------------------------------------------------------------------------
    def inputs_for(self, reader, motion_texts: list[str], shape_texts: list[str | None]) -> tuple:
        """The encoder inputs of a batch of prompts. ``reader``: the T5's tokenizer, or for MiniLM
        the TextEncoder / a StateCache of it."""
        if self.encoder_kind == "minilm":
            inputs = minilm_inputs(reader, motion_texts, shape_texts)
            numbers = (shape_numbers(reader, shape_texts, inputs[0].shape[1]),) if self._head_numbers() else ()
            return inputs + (self.memory_inputs(reader, motion_texts) if self.memory_k else ()) + numbers
        enc = reader([shapemove_prompt(m, s) for m, s in zip(motion_texts, shape_texts)], return_tensors="pt",
                     padding=True, truncation=True, max_length=256)
        return enc.input_ids, enc.attention_mask

    def _head_numbers(self) -> bool:
        """The `[BETA]` head reads the values of the shape text's numbers: ``inputs_for`` appends them
        (last), ``encode`` leaves them out and ``head_text`` hands them to the head."""
        return bool(getattr(self.beta_head, "reads_numbers", False))

    def encode(self, *inputs):
        """(encoder states (B, L, d_model), mask (B, L)) of ``inputs_for``'s inputs."""
        if self.encoder_kind == "minilm":
            return self.lm.encode(*(inputs[:-1] if self._head_numbers() else inputs))
        ids, mask = inputs
        return self.lm.get_encoder()(input_ids=ids, attention_mask=mask).last_hidden_state, mask

    def step(self, enc, mask, decoder_ids, past=None, use_cache: bool = False):
        """Decoder logits (B, T, V), last hidden states (B, T, d) and the cache, for ``decoder_ids``
        (all of them, or with ``past`` only the new ones)."""
        if self.encoder_kind == "minilm":
            return self.lm.step(enc, mask, decoder_ids, past, use_cache)
        from transformers.modeling_outputs import BaseModelOutput

        out = self.lm(encoder_outputs=BaseModelOutput(last_hidden_state=enc), attention_mask=mask,
                      decoder_input_ids=decoder_ids, past_key_values=past, use_cache=use_cache,
                      output_hidden_states=True)
        return out.logits, out.decoder_hidden_states[-1], (out.past_key_values if use_cache else None)

    def beta_state(self, inputs) -> torch.Tensor:
        """(B, d_model) decoder states whose input is `[BETA]`, for ``inputs_for`` inputs (two decoder
        positions, no motion tokens; ``constrained_decoding.decode`` reads the same state)."""
        v = self.vocab
        enc, mask = self.encode(*inputs)
        seq = torch.tensor([[v.pad_id, v.beta_id]] * enc.shape[0], device=enc.device)
        _, hidden, _ = self.step(enc, mask, seq)
        return hidden[:, 1]

    def head_text(self, inputs) -> tuple:
        """What a head that reads the words (``beta_head.reads_text``) gets beside the `[BETA]` state:
        the MiniLM token states of ``inputs_for`` inputs and the mask of the shape text's tokens
        (segment 0, which leads each row); (None, None) for a head that does not read them."""
        if not getattr(self.beta_head, "reads_text", False):
            return None, None
        if self.encoder_kind != "minilm":
            raise ShapeMoveError("a [BETA] head that reads the words needs the MiniLM encoder")
        states, mask, segments = inputs[:3]
        if self._head_numbers():
            return states, mask & (segments == 0), inputs[-1]
        return states, mask & (segments == 0)

    def betas_at(self, hidden_at_beta: torch.Tensor, inputs) -> torch.Tensor:
        """(B, 10) betas from the `[BETA]` states of ``inputs_for`` inputs (the head's one entry point:
        ``predict_betas`` and ``constrained_decoding.decode`` read betas through it)."""
        return self.beta_head(hidden_at_beta, *self.head_text(inputs))

    def predict_betas(self, inputs) -> torch.Tensor:
        """(B, 10) betas of the `[BETA]` head for ``inputs_for`` inputs."""
        return self.betas_at(self.beta_state(inputs), inputs)

    # -- training -----------------------------------------------------------------------------
    def forward(self, inputs_a, inputs_b, labels, betas=None, segments=None, memory=None):
        """``inputs_a``, ``inputs_b``: input ids + attention mask (T5), or MiniLM states + mask with
        ``segments`` (minilm). labels (B,L): [BETA] [SOM] codes [EOM] </s>, padded with -100 (text
        targets for the motion-to-text task have no [BETA]). ``memory``: (ids, sims) of the retrieved
        clips (``memory_inputs``) for a model that reads them. Returns dict(loss, ce, l1, betas_pred)."""
        if self.encoder_kind == "minilm":
            enc, mask = self.lm.encode(inputs_a, inputs_b, segments, *(memory or ()))
            start = torch.full_like(labels[:, :1], self.vocab.pad_id)
            dec_in = torch.cat([start, labels[:, :-1].masked_fill(labels[:, :-1] < 0, self.vocab.pad_id)], 1)
            logits, hidden, _ = self.lm.step(enc, mask, dec_in)
            ce = F.cross_entropy(logits.reshape(-1, logits.shape[-1]).float(), labels.reshape(-1), ignore_index=-100)
        else:
            out = self.lm(input_ids=inputs_a, attention_mask=inputs_b, labels=labels, output_hidden_states=True)
            ce, hidden = out.loss, out.decoder_hidden_states[-1]
        # decoder input is labels shifted right: position i+1 has labels[i] as input, so the state
        # whose INPUT is [BETA] sits one step after [BETA]'s position in labels
        is_beta = labels == self.vocab.beta_id
        has_beta = is_beta.any(1)
        l1 = ce.new_zeros(())
        pred = None
        if has_beta.any():
            pos = is_beta.float().argmax(1) + 1
            pos = pos.clamp(max=hidden.shape[1] - 1)
            h = hidden[torch.arange(hidden.shape[0]), pos][has_beta]
            if self._head_numbers():
                raise ShapeMoveError("a [BETA] head that reads numbers is trained by `train head` on an exported "
                                     "model, not together with the T5")
            text, text_mask = self.head_text((inputs_a, inputs_b, segments))
            pred = self.beta_head(h, *((text[has_beta], text_mask[has_beta]) if text is not None else ()))
            if betas is not None:
                l1 = (pred - betas[has_beta]).abs().mean()
        return {"loss": ce + self.beta_weight * l1, "ce": ce.detach(), "l1": l1.detach(), "betas_pred": pred}

    # -- persistence --------------------------------------------------------------------------
    def save(self, directory: Path, tokenizer=None, meta: dict | None = None, known: dict | None = None,
             memory=None) -> None:
        """Atomic: written into ``directory.tmp`` then renamed over ``directory``. ``known``: the
        training captions/actions and their MiniLM vectors (``known_texts.py``)."""
        import shutil

        from safetensors.torch import save_file

        directory = Path(directory)
        tmp = directory.with_name(directory.name + ".tmp")
        shutil.rmtree(tmp, ignore_errors=True)
        info = {"format": FORMAT, "encoder": self.encoder_kind, "beta_weight": self.beta_weight,
                "d_model": self.d_model, "num_codes": self.vocab.num_codes, **(meta or {}),
                "beta_head": self.beta_head.config()}
        if self.encoder_kind == "minilm":
            from .text_encoder import fingerprint

            tmp.mkdir(parents=True)
            save_file({k: v.contiguous() for k, v in self.lm.state_dict().items()}, str(tmp / "model.safetensors"),
                      metadata={"format": "pt"})
            (tmp / "config.json").write_text(self.lm.config.to_json_string())
            info["text_encoder"] = fingerprint()
        else:
            if tokenizer is None:
                raise ShapeMoveError("saving a T5 ShapeMove model needs its tokenizer")
            self.lm.save_pretrained(str(tmp), safe_serialization=True)
            tokenizer.save_pretrained(str(tmp))
            info["tokenizer_sha256"] = sha256_file(tmp / "tokenizer.json")
        save_file({k: v.contiguous() for k, v in self.beta_head.state_dict().items()}, str(tmp / "beta_head.safetensors"))
        if known is not None:
            from .known_texts import write_known

            write_known(tmp, known)
        if memory is not None:
            memory.save(tmp)
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
        """(model in eval mode, text reader): the T5's tokenizer, or the verified MiniLM."""
        from safetensors.torch import load_file

        directory = Path(directory)
        info_file = directory / "shapemove.json"
        if not info_file.is_file():
            raise ShapeMoveError(f"{directory} is not a ShapeMove T5 model (no shapemove.json)")
        with damaged_model_errors(directory):
            info = json.loads(info_file.read_text())
        if not isinstance(info, dict) or info.get("format") not in (FORMAT, FORMAT_V1):
            raise ShapeMoveError(f"{directory}: unsupported model format "
                                 f"{info.get('format') if isinstance(info, dict) else info!r} (expected {FORMAT})")
        encoder = info.get("encoder", "t5") if info["format"] == FORMAT else "t5"
        if encoder not in ENCODERS:
            raise ShapeMoveError(f"{directory}: unknown text encoder {encoder!r} in shapemove.json")
        verify_manifest(directory, required=MINILM_FILES if encoder == "minilm" else T5_FILES)
        with damaged_model_errors(directory):
            if encoder == "minilm":
                from .t5_decoder import T5DecoderConfig
                from .text_encoder import HIDDEN, check_fingerprint, load_text_encoder
                from .tokenizer import MotionVocab

                check_fingerprint(info.get("text_encoder"), str(directory))
                reader = load_text_encoder()
                cfg = T5DecoderConfig.from_dict(json.loads((directory / "config.json").read_text()))
                vocab = MotionVocab.motion_only(int(info.get("num_codes", 0)))
                if cfg.vocab_size != vocab.vocab_size:
                    raise ShapeMoveError(f"{directory}: config.json has {cfg.vocab_size} tokens, shapemove.json "
                                         f"{info.get('num_codes')} motion codes; the folder is inconsistent")
                lm = MiniLMDecoder(cfg, HIDDEN)
                lm.load_state_dict({k: v.float() for k, v in load_file(str(directory / "model.safetensors")).items()})
            else:
                from transformers import T5ForConditionalGeneration

                from .tokenizer import MotionVocab, load_tokenizer

                recorded = info.get("tokenizer_sha256")
                if recorded is not None and sha256_file(directory / "tokenizer.json") != recorded:
                    raise ShapeMoveError(f"{directory}: tokenizer.json is not the tokenizer this model was trained "
                                         "with (sha256 differs); copy the whole model folder again")
                reader = load_tokenizer(directory, num_codes=info.get("num_codes"))
                lm = T5ForConditionalGeneration.from_pretrained(str(directory), local_files_only=True,
                                                                dtype=torch.float32)
                vocab = MotionVocab(reader, info.get("num_codes"))
                if lm.config.vocab_size < vocab.vocab_size:
                    raise ShapeMoveError(f"{directory}: the tokenizer has {vocab.vocab_size} tokens, the model "
                                         f"only {lm.config.vocab_size}: tokenizer and model do not match")
            head = build_head(info.get("beta_head"), lm.config.d_model)  # no entry: the first (MLP) head
            if head.reads_text and encoder != "minilm":
                raise ShapeMoveError(f"{directory}: its [BETA] head reads MiniLM states, but the model's "
                                     f"encoder is {encoder}")
            head.load_state_dict({k: v.float() for k, v in load_file(str(directory / "beta_head.safetensors")).items()})
        model = cls(lm, head, vocab, info.get("beta_weight", 1.0), encoder)
        model.info = info
        from .motion_codes import token_limit
        from .motion_memory import MEMORY_JSON, MEMORY_TENSORS, MotionMemory

        model.memory = MotionMemory.load(directory)  # a model that does not read it still retrieves candidates
        if model.memory is None and model.memory_k:
            raise ShapeMoveError(f"{directory}: this model reads retrieved clips but {MEMORY_JSON} and "
                                 f"{MEMORY_TENSORS} are missing; copy the whole model folder again")
        if model.memory is not None:
            # tokens are base codes, or base codes with a residual packed in (motion_codes.py); the
            # SA-VAE checks the residual's range when it decodes one
            bad = [c for c, t in zip(model.memory.clip_ids, model.memory.clip_tokens)
                   if len(t) and (t.min() < 0 or t.max() >= token_limit(vocab.num_codes))]
            if bad:
                raise ShapeMoveError(f"{directory}: {MEMORY_TENSORS} holds codes outside the model's "
                                     f"{vocab.num_codes} (clip {bad[0]}); copy the model folder again")
        return model.eval(), reader


def minilm_inputs(reader, motion_texts: list[str], shape_texts: list[str | None]) -> tuple:
    """(states (B, L, 384), mask (B, L), segments (B, L)): each sample's shape-text states
    (segment 0, when it has one) followed by its motion-text states (segment 1)."""
    from .text_encoder import HIDDEN

    n = len(motion_texts)
    ms, mm = reader.states(list(motion_texts))
    has_shape = [i for i, s in enumerate(shape_texts) if s and str(s).strip()]
    ss, sm = reader.states([shape_texts[i] for i in has_shape]) if has_shape else (None, None)
    parts = []
    for i in range(n):
        m = ms[i][mm[i]]
        if i in has_shape:
            k = has_shape.index(i)
            s = ss[k][sm[k]]
            parts.append((torch.cat([s, m]), len(s)))
        else:
            parts.append((m, 0))
    L = max(len(p) for p, _ in parts)
    states = torch.zeros(n, L, HIDDEN)
    mask = torch.zeros(n, L, dtype=torch.bool)
    seg = torch.ones(n, L, dtype=torch.long)
    for i, (p, k) in enumerate(parts):
        states[i, : len(p)] = p
        mask[i, : len(p)] = True
        seg[i, :k] = 0
    return states, mask, seg


def shape_numbers(reader, shape_texts: list[str | None], length: int) -> torch.Tensor:
    """(B, length, F) value features of the numbers in each shape text (``text_numbers``), in the
    rows of ``minilm_inputs``'s states where that text's tokens sit (first in each row)."""
    from .text_numbers import FEATURES, number_features

    tokenizer = reader.tokenizer if hasattr(reader, "tokenizer") else reader.encoder.tokenizer
    out = torch.zeros(len(shape_texts), length, FEATURES)
    has = [i for i, s in enumerate(shape_texts) if s and str(s).strip()]
    for i, f in zip(has, number_features(tokenizer, [str(shape_texts[i]) for i in has])):
        out[i, :len(f)] = f
    return out


def size_from_dict(d: dict) -> T5Size:
    return T5Size(**{k: v for k, v in d.items() if k in asdict(T5Size())})
