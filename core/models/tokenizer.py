"""The ShapeMove tokenizer: a sentencepiece model trained on the captions and shape texts,
wrapped as a ``transformers`` T5 tokenizer, plus the motion vocabulary.

Added tokens (one id each, never split): ``[MID_0]`` … ``[MID_{N-1}]`` (the SA-VAE's FSQ codes,
N = the FSQ's codebook size, 1000 for levels [8,5,5,5]), ``[SOM]``/``[EOM]`` (start/end of motion)
and ``[BETA]`` (its decoder state is projected to betas). A user-supplied pretrained T5 directory
brings its own tokenizer; the same tokens are added to it.

The default model reads prompts with the pretrained MiniLM (``text_encoder.py``) and its decoder
writes only motion: ``MotionVocab.motion_only(N)`` is that decoder's own small vocabulary
(pad, </s>, [BETA], [SOM], [EOM], N codes).
"""
from __future__ import annotations

from pathlib import Path

from ..constants import NUM_CODES  # the default FSQ codebook; models record their own count
from ..errors import ShapeMoveError
from ..model_files import damaged_model_errors, verify_manifest

SOM, EOM, BETA = "[SOM]", "[EOM]", "[BETA]"
MOTION_TOKENS = [f"[MID_{i}]" for i in range(NUM_CODES)]
MAX_CODES_LIMIT = 1 << 16


def motion_tokens(num_codes: int = NUM_CODES) -> list[str]:
    return [f"[MID_{i}]" for i in range(int(num_codes))]


def train_sentencepiece(texts: list[str], out_prefix: Path, vocab_size: int = 2000, seed: int = 0) -> Path:
    """Unigram sentencepiece model on ``texts``; ids 0/1/2 are pad/eos/unk as T5 expects.
    ``vocab_size`` is an upper bound: a small corpus gets the largest vocabulary it supports."""
    import sentencepiece as spm

    texts = [t.strip() for t in texts if t and t.strip()]
    if not texts:
        raise ShapeMoveError("no texts to train the tokenizer on")
    out_prefix = Path(out_prefix)
    out_prefix.parent.mkdir(parents=True, exist_ok=True)
    corpus = out_prefix.with_suffix(".corpus.txt")
    corpus.write_text("\n".join(texts) + "\n", encoding="utf-8")
    spm.SentencePieceTrainer.train(
        input=str(corpus), model_prefix=str(out_prefix), vocab_size=vocab_size, model_type="unigram",
        pad_id=0, eos_id=1, unk_id=2, bos_id=-1, hard_vocab_limit=False, character_coverage=1.0,
        num_threads=1, minloglevel=2, normalization_rule_name="nmt_nfkc_cf",
    )
    corpus.unlink()
    return out_prefix.with_suffix(".model")


def tokenizer_from_sentencepiece(model_file: Path, num_codes: int = NUM_CODES):
    """A T5 tokenizer whose vocabulary is the sentencepiece model's, plus the motion tokens."""
    import sentencepiece as spm
    from tokenizers import normalizers
    from transformers import T5Tokenizer

    sp = spm.SentencePieceProcessor(model_file=str(model_file))
    vocab = [(sp.id_to_piece(i), float(sp.get_score(i))) for i in range(sp.get_piece_size())]
    vocab[0], vocab[1], vocab[2] = ("<pad>", 0.0), ("</s>", 0.0), ("<unk>", 0.0)
    tok = T5Tokenizer(vocab=vocab, extra_ids=0)
    # the pieces were learnt on NFKC + case-folded text: normalise the same way at run time
    tok.backend_tokenizer.normalizer = normalizers.Sequence([normalizers.NFKC(), normalizers.Lowercase()])
    return add_motion_tokens(tok, num_codes)


def add_motion_tokens(tok, num_codes: int = NUM_CODES):
    """Add the motion/shape tokens as special tokens (idempotent); returns the tokenizer."""
    missing = [t for t in motion_tokens(num_codes) + [SOM, EOM, BETA]
               if tok.convert_tokens_to_ids(t) in (None, tok.unk_token_id)]
    if missing:
        tok.add_tokens(missing, special_tokens=True)
    return tok


def load_tokenizer(directory: Path, require_json: bool = True, num_codes: int | None = None):
    """The tokenizer saved in ``directory`` with the motion tokens. ``require_json``: a ShapeMove
    model folder must hold its ``tokenizer.json`` (a pretrained T5 folder may bring only
    ``spiece.model``); without it transformers would quietly build a different tokenizer."""
    from transformers import AutoTokenizer

    directory = Path(directory)
    if not directory.is_dir():
        raise ShapeMoveError(f"tokenizer folder not found: {directory}")
    if require_json and not (directory / "tokenizer.json").is_file():
        raise ShapeMoveError(f"{directory}: the model's tokenizer (tokenizer.json) is missing; the folder is "
                             "incomplete: copy the whole model folder again or retrain")

    verify_manifest(directory)  # sha256 of the files when a manifest lists them
    with damaged_model_errors(directory):
        tok = AutoTokenizer.from_pretrained(str(directory), local_files_only=True)
    saved = directory / "tokenizer.json"
    if saved.is_file() and getattr(tok, "backend_tokenizer", None) is not None:
        # some tokenizer classes rebuild their pipeline on load and drop the saved normalizer
        from tokenizers import Tokenizer

        with damaged_model_errors(directory):
            normalizer = Tokenizer.from_file(str(saved)).normalizer
        if normalizer is not None and tok.backend_tokenizer.normalizer is None:
            tok.backend_tokenizer.normalizer = normalizer
    if num_codes is None:
        num_codes = count_motion_tokens(tok) or NUM_CODES
    return add_motion_tokens(tok, num_codes)


def count_motion_tokens(tok) -> int:
    """How many [MID_i] tokens the tokenizer already has (0 for a fresh one)."""
    vocab = tok.get_vocab()
    n = 0
    while n < MAX_CODES_LIMIT and f"[MID_{n}]" in vocab:
        n += 1
    return n


class MotionVocab:
    """Ids of the added tokens in a given tokenizer, and code <-> token-id conversion."""

    def __init__(self, tok=None, num_codes: int | None = None):
        if tok is None:  # filled in by motion_only()
            return
        self.num_codes = int(num_codes) if num_codes is not None else (count_motion_tokens(tok) or NUM_CODES)
        self.first_code_id = tok.convert_tokens_to_ids("[MID_0]")
        ids = tok.convert_tokens_to_ids(motion_tokens(self.num_codes))
        if ids != list(range(self.first_code_id, self.first_code_id + self.num_codes)):
            raise ShapeMoveError("motion tokens are not contiguous in this tokenizer")
        self.som_id = tok.convert_tokens_to_ids(SOM)
        self.eom_id = tok.convert_tokens_to_ids(EOM)
        self.beta_id = tok.convert_tokens_to_ids(BETA)
        self.pad_id = tok.pad_token_id
        self.eos_id = tok.eos_token_id
        self.vocab_size = len(tok)

    @classmethod
    def motion_only(cls, num_codes: int) -> "MotionVocab":
        """The vocabulary of a decoder that only writes motion: pad 0, </s> 1, [BETA] 2, [SOM] 3,
        [EOM] 4, then the codes."""
        if not 2 <= int(num_codes) <= MAX_CODES_LIMIT:
            raise ShapeMoveError(f"motion vocabulary of {num_codes} codes: expected 2..{MAX_CODES_LIMIT}")
        v = cls()
        v.pad_id, v.eos_id, v.beta_id, v.som_id, v.eom_id = 0, 1, 2, 3, 4
        v.first_code_id, v.num_codes = 5, int(num_codes)
        v.vocab_size = 5 + v.num_codes
        return v

    def codes_to_ids(self, codes):
        return [self.first_code_id + int(c) for c in codes]

    def ids_to_codes(self, ids):
        return [int(i) - self.first_code_id for i in ids if self.is_code(i)]

    def is_code(self, i) -> bool:
        return self.first_code_id <= int(i) < self.first_code_id + self.num_codes

    def target_ids(self, codes) -> list[int]:
        """Decoder target of the text-to-motion task: [BETA] [SOM] codes… [EOM] </s>."""
        return [self.beta_id, self.som_id, *self.codes_to_ids(codes), self.eom_id, self.eos_id]
