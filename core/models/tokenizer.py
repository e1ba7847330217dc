"""The ShapeMove tokenizer: a sentencepiece model trained on the captions and shape texts,
wrapped as a ``transformers`` T5 tokenizer, plus the motion vocabulary.

Added tokens (one id each, never split): ``[MID_0]`` … ``[MID_999]`` (the SA-VAE's FSQ codes),
``[SOM]``/``[EOM]`` (start/end of motion) and ``[BETA]`` (its decoder state is projected to betas).
A user-supplied pretrained T5 directory brings its own tokenizer; the same tokens are added to it.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ShapeMoveError

NUM_CODES = 1000
SOM, EOM, BETA = "[SOM]", "[EOM]", "[BETA]"
MOTION_TOKENS = [f"[MID_{i}]" for i in range(NUM_CODES)]


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


def tokenizer_from_sentencepiece(model_file: Path):
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
    return add_motion_tokens(tok)


def add_motion_tokens(tok):
    """Add the motion/shape tokens as special tokens (idempotent); returns the tokenizer."""
    missing = [t for t in MOTION_TOKENS + [SOM, EOM, BETA] if tok.convert_tokens_to_ids(t) in (None, tok.unk_token_id)]
    if missing:
        tok.add_tokens(missing, special_tokens=True)
    return tok


def load_tokenizer(directory: Path):
    from transformers import AutoTokenizer

    directory = Path(directory)
    if not directory.is_dir():
        raise ShapeMoveError(f"tokenizer folder not found: {directory}")
    tok = AutoTokenizer.from_pretrained(str(directory), local_files_only=True)
    saved = directory / "tokenizer.json"
    if saved.is_file() and getattr(tok, "backend_tokenizer", None) is not None:
        # some tokenizer classes rebuild their pipeline on load and drop the saved normalizer
        from tokenizers import Tokenizer

        normalizer = Tokenizer.from_file(str(saved)).normalizer
        if normalizer is not None and tok.backend_tokenizer.normalizer is None:
            tok.backend_tokenizer.normalizer = normalizer
    return add_motion_tokens(tok)


class MotionVocab:
    """Ids of the added tokens in a given tokenizer, and code <-> token-id conversion."""

    def __init__(self, tok):
        self.first_code_id = tok.convert_tokens_to_ids(MOTION_TOKENS[0])
        ids = tok.convert_tokens_to_ids(MOTION_TOKENS)
        if ids != list(range(self.first_code_id, self.first_code_id + NUM_CODES)):
            raise ShapeMoveError("motion tokens are not contiguous in this tokenizer")
        self.som_id = tok.convert_tokens_to_ids(SOM)
        self.eom_id = tok.convert_tokens_to_ids(EOM)
        self.beta_id = tok.convert_tokens_to_ids(BETA)
        self.pad_id = tok.pad_token_id
        self.eos_id = tok.eos_token_id
        self.vocab_size = len(tok)

    def codes_to_ids(self, codes):
        return [self.first_code_id + int(c) for c in codes]

    def ids_to_codes(self, ids):
        return [int(i) - self.first_code_id for i in ids if self.is_code(i)]

    def is_code(self, i) -> bool:
        return self.first_code_id <= int(i) < self.first_code_id + NUM_CODES

    def target_ids(self, codes) -> list[int]:
        """Decoder target of the text-to-motion task: [BETA] [SOM] codes… [EOM] </s>."""
        return [self.beta_id, self.som_id, *self.codes_to_ids(codes), self.eom_id, self.eos_id]
