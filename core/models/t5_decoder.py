"""A T5 decoder stack in plain torch: the same layers, weights (state-dict names) and maths as
``transformers``' ``T5Stack`` used as a decoder (RMS layer norms, unscaled attention, learned
relative-position buckets in the first self-attention shared by all layers, cross-attention without
position bias, ReLU feed-forward), with a key/value cache for generation. ShapeMove's default
decoder uses it so that loading and running a model never imports ``transformers`` (~4 s of CPU);
``tests/test_t5_decoder.py`` checks outputs, cache and gradients against ``T5Stack``.

    cfg = T5DecoderConfig(vocab_size=1005, d_model=128, d_ff=512, d_kv=32, num_heads=4, num_layers=3)
    dec = T5Decoder(cfg)
    hidden, cache = dec(ids, enc_states, enc_mask, cache=None, use_cache=True)
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass

import torch
import torch.nn.functional as F
from torch import nn


@dataclass
class T5DecoderConfig:
    vocab_size: int
    d_model: int = 256
    d_ff: int = 1024
    d_kv: int = 64
    num_heads: int = 4
    num_layers: int = 4
    dropout_rate: float = 0.1
    relative_attention_num_buckets: int = 32
    relative_attention_max_distance: int = 128
    layer_norm_epsilon: float = 1e-6
    # ShapeMove's MiniLM reader (shapemove_t5.MiniLMDecoder), not the stack: a memory slot holding the
    # prompt's pooled sentence vector, and the share of training examples whose motion-text token
    # states are hidden so that the decoder learns to read that sentence vector
    sentence_token: bool = False
    text_dropout: float = 0.0
    # retrieval memory (shapemove_t5.MiniLMDecoder, ``motion_memory.py``): the motion tokens of the
    # ``memory_k`` clips whose captions are nearest to the prompt, ``memory_codes`` each, read as extra
    # cross-attention memory; ``memory_dropout``: share of training prompts given none
    memory_k: int = 0
    memory_codes: int = 40
    memory_dropout: float = 0.0

    def to_json_string(self) -> str:
        return json.dumps({"model_type": "t5-decoder", **asdict(self)}, indent=2)

    @classmethod
    def from_dict(cls, d: dict) -> "T5DecoderConfig":
        # also reads a transformers T5Config's config.json (num_decoder_layers, feed_forward_proj relu)
        if d.get("feed_forward_proj", "relu") != "relu":
            raise ValueError(f"feed_forward_proj {d.get('feed_forward_proj')!r} is not supported")
        n = d.get("num_layers", d.get("num_decoder_layers"))
        keys = set(asdict(cls(vocab_size=1))) - {"num_layers"}
        return cls(num_layers=int(n), **{k: d[k] for k in keys if k in d})


class RMSNorm(nn.Module):
    def __init__(self, d: int, eps: float):
        super().__init__()
        self.weight = nn.Parameter(torch.ones(d))
        self.eps = eps

    def forward(self, x):
        var = x.float().pow(2).mean(-1, keepdim=True)
        return self.weight * (x * torch.rsqrt(var + self.eps)).to(self.weight.dtype)


class Attention(nn.Module):
    def __init__(self, cfg: T5DecoderConfig, relative_bias: bool):
        super().__init__()
        inner = cfg.num_heads * cfg.d_kv
        self.h, self.dk = cfg.num_heads, cfg.d_kv
        self.q = nn.Linear(cfg.d_model, inner, bias=False)
        self.k = nn.Linear(cfg.d_model, inner, bias=False)
        self.v = nn.Linear(cfg.d_model, inner, bias=False)
        self.o = nn.Linear(inner, cfg.d_model, bias=False)
        self.dropout = cfg.dropout_rate
        if relative_bias:
            self.relative_attention_bias = nn.Embedding(cfg.relative_attention_num_buckets, cfg.num_heads)

    def split(self, x):
        return x.view(x.shape[0], -1, self.h, self.dk).transpose(1, 2)

    def forward(self, x, kv, bias, past=None, static_kv: bool = False):
        """x (B,T,d); kv: the states keys/values come from; bias (B|1, H, T, S) additive; past:
        (k, v) cached. Returns (out, (k, v))."""
        q = self.split(self.q(x))
        if static_kv and past is not None:
            k, v = past
        else:
            k, v = self.split(self.k(kv)), self.split(self.v(kv))
            if past is not None:
                k, v = torch.cat([past[0], k], 2), torch.cat([past[1], v], 2)
        scores = torch.matmul(q, k.transpose(-1, -2)) + bias  # T5: no 1/sqrt(d_kv)
        w = F.dropout(torch.softmax(scores.float(), -1).type_as(scores), self.dropout, self.training)
        out = torch.matmul(w, v).transpose(1, 2).reshape(x.shape[0], -1, self.h * self.dk)
        return self.o(out), (k, v)


class _SelfLayer(nn.Module):
    def __init__(self, cfg, relative_bias):
        super().__init__()
        self.SelfAttention = Attention(cfg, relative_bias)
        self.layer_norm = RMSNorm(cfg.d_model, cfg.layer_norm_epsilon)


class _CrossLayer(nn.Module):
    def __init__(self, cfg):
        super().__init__()
        self.EncDecAttention = Attention(cfg, False)
        self.layer_norm = RMSNorm(cfg.d_model, cfg.layer_norm_epsilon)


class _DenseReluDense(nn.Module):
    def __init__(self, cfg):
        super().__init__()
        self.wi = nn.Linear(cfg.d_model, cfg.d_ff, bias=False)
        self.wo = nn.Linear(cfg.d_ff, cfg.d_model, bias=False)


class _FFLayer(nn.Module):
    def __init__(self, cfg):
        super().__init__()
        self.DenseReluDense = _DenseReluDense(cfg)
        self.layer_norm = RMSNorm(cfg.d_model, cfg.layer_norm_epsilon)


class _Block(nn.Module):
    def __init__(self, cfg, first: bool):
        super().__init__()
        self.layer = nn.ModuleList([_SelfLayer(cfg, first), _CrossLayer(cfg), _FFLayer(cfg)])


def relative_buckets(rel: torch.Tensor, num_buckets: int, max_distance: int) -> torch.Tensor:
    """T5's causal (unidirectional) bucketing of key - query offsets."""
    rel = -torch.clamp(rel, max=0)
    exact = num_buckets // 2
    large = exact + (torch.log(rel.float().clamp(min=1) / exact) / math.log(max_distance / exact)
                     * (num_buckets - exact)).to(torch.long)
    large = torch.clamp(large, max=num_buckets - 1)
    return torch.where(rel < exact, rel, large)


class T5Decoder(nn.Module):
    def __init__(self, cfg: T5DecoderConfig):
        super().__init__()
        self.config = cfg
        self.embed_tokens = nn.Embedding(cfg.vocab_size, cfg.d_model)
        self.block = nn.ModuleList([_Block(cfg, i == 0) for i in range(cfg.num_layers)])
        self.final_layer_norm = RMSNorm(cfg.d_model, cfg.layer_norm_epsilon)
        self.dropout = nn.Dropout(cfg.dropout_rate)
        self.reset_parameters()

    @torch.no_grad()
    def reset_parameters(self):
        """T5's initialisation (``T5PreTrainedModel._init_weights`` with factor 1)."""
        c = self.config
        self.embed_tokens.weight.normal_(0.0, 1.0)
        for m in self.modules():
            if isinstance(m, Attention):
                m.q.weight.normal_(0.0, (c.d_model * c.d_kv) ** -0.5)
                m.k.weight.normal_(0.0, c.d_model ** -0.5)
                m.v.weight.normal_(0.0, c.d_model ** -0.5)
                m.o.weight.normal_(0.0, (c.num_heads * c.d_kv) ** -0.5)
                if hasattr(m, "relative_attention_bias"):
                    m.relative_attention_bias.weight.normal_(0.0, c.d_model ** -0.5)
            elif isinstance(m, _DenseReluDense):
                m.wi.weight.normal_(0.0, c.d_model ** -0.5)
                m.wo.weight.normal_(0.0, c.d_ff ** -0.5)
            elif isinstance(m, RMSNorm):
                m.weight.fill_(1.0)

    def position_bias(self, q_len: int, k_len: int, offset: int, device) -> torch.Tensor:
        """(1, H, q_len, k_len): relative-position bias + causal mask, queries at offset.. ."""
        c = self.config
        qpos = torch.arange(offset, offset + q_len, device=device)[:, None]
        kpos = torch.arange(k_len, device=device)[None]
        buckets = relative_buckets(kpos - qpos, c.relative_attention_num_buckets, c.relative_attention_max_distance)
        bias = self.block[0].layer[0].SelfAttention.relative_attention_bias(buckets).permute(2, 0, 1)[None]
        return bias.masked_fill(kpos > qpos, torch.finfo(bias.dtype).min)

    def forward(self, ids, enc, enc_mask, cache=None, use_cache: bool = False):
        """ids (B,T) decoder inputs (with ``cache``: only the new ones); enc (B,S,d), enc_mask (B,S).
        Returns (last hidden states (B,T,d), cache or None)."""
        offset = 0 if cache is None else cache[0][0][0].shape[2]
        x = self.dropout(self.embed_tokens(ids))
        self_bias = self.position_bias(ids.shape[1], offset + ids.shape[1], offset, ids.device)
        cross_bias = torch.zeros(enc_mask.shape, dtype=x.dtype, device=x.device)
        cross_bias = cross_bias.masked_fill(~enc_mask.bool(), torch.finfo(x.dtype).min)[:, None, None, :]
        new_cache = []
        for i, blk in enumerate(self.block):
            s, c, f = blk.layer
            past_self, past_cross = (cache[i] if cache is not None else (None, None))
            n = s.layer_norm(x)
            a, kv_self = s.SelfAttention(n, n, self_bias, past_self)
            x = x + self.dropout(a)
            a, kv_cross = c.EncDecAttention(c.layer_norm(x), enc, cross_bias, past_cross, static_kv=True)
            x = x + self.dropout(a)
            d = f.DenseReluDense
            x = x + self.dropout(d.wo(self.dropout(F.relu(d.wi(f.layer_norm(x))))))
            new_cache.append((kv_self, kv_cross))
        x = self.dropout(self.final_layer_norm(x))
        return x, (new_cache if use_cache else None)
