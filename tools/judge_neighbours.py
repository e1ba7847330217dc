"""What the TMA judge of ``eval paraphrase`` reads a real clip or a prompt's motion by: the 5 nearest
training clips (their action and id) of each 4 s window of the built dataset's clips, or of the
motion a prompt makes, each judged without its own take, as ``eval paraphrase`` judges.

    python tools/judge_neighbours.py --data data/built --clip cmu_105_02 cmu_105_03
    python tools/judge_neighbours.py --data data/built --prompt "a man walks in a figure eight" --seed 0 1

Used for the figure eight (docs/evaluation.md): the judge's references of "walk in a figure eight"
are one performer's takes (CMU subject 105), and it reads that performer's straight walk as one.
"""
from __future__ import annotations

import argparse

import numpy as np

WINDOW = 80   # frames: 4 s at 20 fps, what ``eval paraphrase`` plays
STEP = 60     # frames between a clip's windows


def neighbours(classifier, emb: np.ndarray, exclude: list[str], k: int = 5) -> tuple[str, list[tuple[str, str, float]]]:
    """(the judge's vote, its ``k`` nearest references as (action, clip id, cosine)) of a TMA motion
    embedding, the takes of ``exclude`` left out."""
    from shapemove.core.models.motion_memory import take_of

    e = np.asarray(emb, np.float32) / max(float(np.linalg.norm(emb)), 1e-8)
    sims = classifier.embeddings @ e
    sims[np.isin([take_of(s) for s in classifier.sources], [take_of(c) for c in exclude])] = -np.inf
    top = np.argsort(-sims)[:k]
    vote = classifier.classify_embeddings(e[None], exclude=[list(exclude)])[0]
    return vote, [(classifier.labels[i], classifier.ids[i], float(sims[i])) for i in top]


def main(argv=None) -> int:
    from shapemove.core.eval.action_classifier import ActionClassifier, load_features
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.model_bundle import model_files
    from shapemove.core.models.tma_embed import embed_motions, load_tma
    from shapemove.core.motion.features import motion_features

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--data", required=True, help="the built dataset (data/built)")
    p.add_argument("--model", default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--clip", nargs="*", default=[], help="built clip ids whose 4 s windows are judged")
    p.add_argument("--prompt", nargs="*", default=[], help="prompts whose 4 s motions are judged")
    p.add_argument("--seed", type=int, nargs="*", default=[0])
    a = p.parse_args(argv)
    gen = Generator(a.model)
    model, tok, mean, std = tma = load_tma(model_files(gen.model_dir)["tma"])
    judge = ActionClassifier.from_data(tma, a.data, gen.known_actions, progress=False)

    def show(name: str, feats, exclude: list[str]) -> None:
        vote, near = neighbours(judge, embed_motions(model, [feats], mean, std)[0], exclude)
        print(f"{name}: {vote} <- " + ", ".join(f"{act} {cid} {s:.3f}" for act, cid, s in near))

    for cid in a.clip:
        f = load_features(a.data, cid)
        if f is None:
            print(f"{cid}: no features in {a.data}")
            continue
        for s in range(0, max(1, len(f) - WINDOW + 1), STEP):
            show(f"{cid} {s / 20:.0f}-{(s + WINDOW) / 20:.0f} s", f[s:s + WINDOW], [cid])
    for text in a.prompt:
        for seed in a.seed:
            m = gen.generate_batch([Request(text, seconds=WINDOW / 20, seed=seed)])[0]
            show(f"{text!r} seed {seed} ({m.provenance})", motion_features(m), list(m.retrieved_clips))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
