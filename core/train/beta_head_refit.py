"""The `[BETA]` head's second phase: the T5 frozen, only the head trained, on body measurements.

Stage 2 trains the head jointly with the decoder on an L1 loss over the 10 betas. Not every beta
matters to how a body looks, and a shape text states heights and girths, so after the main steps
``head_steps`` more steps train the head alone on

    L1(betas) + ``head_measure_weight`` * (|height - true height| + |waist - true waist|)   (cm)

with height and waist of both bodies from ``shape_from_measurements.torch_measure`` (exact height
of the rest mesh, waist from the body's betas -> girth regression), so the loss reads the same
numbers the evaluation does. The decoder runs in eval mode without gradients (as at generation
time) and only for the two positions up to `[BETA]`, so a step costs a few milliseconds; examples
are drawn as in the main phase (captions, shape texts, none for a share of them), and a share
``head_synthetic_share`` describes NEW random bodies (``synthetic_bodies``, a pool of ``head_synthetic_bodies``): the dataset has a
few real skeletons and ~1,400 augmented bodies, and a head trained on those alone reads the numbers
of bodies it has seen far better than of new ones (``eval shape`` measures new ones).

``train head`` (``train_head.py``: a new head for an exported model, the T5 frozen) draws from the
same examples (``HeadExamples.fixed``) with a pool that also states weights and words more ways
(``synthetic_pool``, ``stated_text``), and adds what ``eval shape-words`` reads back from the betas,
differentiable (``Readback``: the phenotype sliders through OpenBody's linear map, the mass of the
mesh as an exact cubic in the betas).
"""
from __future__ import annotations

import torch

MEASURES = ("height_cm", "waist_cm")


def head_loss(head, states: torch.Tensor, betas: torch.Tensor, measure, weight: float, text=None, text_mask=None,
              extra=None, l1_target=None, numbers=None, mass=None, mass_weight: float = 0.0, units=None) -> tuple:
    """(loss, L1 of the betas, mean |height error| + |waist error| in cm). ``measure``: (B,10) -> (B,2) cm.
    ``text``/``text_mask``/``numbers``: the shape text's MiniLM states and its numbers' value
    features for a head that reads them; ``extra``:
    (B,10) predicted betas -> a further loss term (``Readback.loss``); ``l1_target``: the betas the
    L1 reads instead of ``betas`` (which the measurements still read). A head that meets the sizes it
    reads (``TextBetaHead`` with ``meets``) is trained on its betas before ``meet`` and, beside them,
    on the height (x ``weight``) and mass (``mass``: (B,10) -> (B,) kg, x ``mass_weight``) it reads;
    one that reads the numbers' units (meets 3) on ``units`` instead: (B, L) the unit of each
    number's first word piece (``number_units.unit_labels``; -100 elsewhere), by cross-entropy."""
    args = (states, text, text_mask, *((numbers,) if getattr(head, "reads_numbers", False) else ()))
    said = None
    if getattr(head, "sizes", {}).get("meets"):
        head.reading_sizes = True
        try:
            pred, said = head(*args)
        finally:
            head.reading_sizes = False
    else:
        pred = head(*args)
    l1 = (pred - (betas if l1_target is None else l1_target)).abs().mean()
    with torch.no_grad():
        true = measure(betas)
    cm = (measure(pred) - true).abs().mean(0).sum()
    loss = l1 + weight * cm
    if units is not None:
        logits, start, _ = head.units.logits(text * text_mask[..., None], numbers)   # as ``forward`` reads it
        labels = units[:, :logits.shape[1]]
        keep = start & (labels >= 0)
        if keep.any():
            loss = loss + torch.nn.functional.cross_entropy(logits[keep], labels[keep])
    elif said is not None:
        with torch.no_grad():
            true_kg = mass(betas)
        loss = loss + weight * (said[:, 0] - true[:, 0]).abs().mean() + mass_weight * (said[:, 1] - true_kg).abs().mean()
    if extra is not None:
        loss = loss + extra(pred)
    return loss, l1.detach(), cm.detach()


def synthetic_bodies(body, girths, seed: int, n: int) -> tuple[list[str], torch.Tensor]:
    """A pool of ``n`` NEW bodies, the same for a seed: drawn from phenotypes (gender, age, muscle,
    weight, height: ``body.phenotype_sample``) when the body model has a phenotype map, else betas
    ~ N(0,1) clipped to +-2.5; measured (``fast_measure``: exact height and lengths, girths from
    ``girths``); each described either in the words people use (``phenotype_texts``: "a muscular
    young man", "a 72-year-old woman, slim", "a man, 6 ft 2") or by one of the dataset's
    measurement texts (the long sentence, a short numeric text or size words). (shape texts,
    (n, 10) betas). The head phase encodes the pool once and draws from it. ``synthetic_pool``
    with ``stated_share`` > 0 also states weights and varies the wording more."""
    texts, betas, _ = synthetic_pool(body, girths, seed, n)
    return texts, betas


def synthetic_pool(body, girths, seed: int, n: int, stated_share: float = 0.0, teen_share: float = 0.0,
                   height_margin: float = 0.0) -> tuple:
    """``synthetic_bodies``'s pool plus each body's phenotype: (shape texts, (n, 10) betas, (n, P)
    phenotype sliders (P = 0 without a phenotype map)). ``stated_share`` > 0 (phenotype map
    needed): the bodies are also weighed (mass from the mesh volume, so phenotype texts state kg
    and lb too) and that share of them is described by ``stated_text`` (more nouns and build words,
    height and weight in the units people type) instead. ``teen_share``, ``height_margin``:
    ``phenotype_sample.sample_phenotypes``'s (teenagers; tall women and short men)."""
    import random

    import numpy as np

    from ..body.measure import MEASUREMENTS
    from ..body.phenotype_sample import sample_bodies
    from ..body.shape_from_measurements import fast_measure
    from ..data.phenotype_captions import phenotype_texts
    from ..data.shape_text import adjective_shape_text, numeric_shape_text, shape_sentence

    rng = random.Random(seed)
    pmap = getattr(body, "phenotype_map", None)
    if pmap is not None:
        pheno, b = sample_bodies(pmap, seed, n, pmap.r2, teen_share, height_margin)
    else:
        pheno, b = np.zeros((n, 0)), np.clip(np.random.default_rng(seed).standard_normal((n, body.num_betas)), -2.5, 2.5)
    keys = list(MEASUREMENTS) + (["mass_kg"] if stated_share > 0 and pmap is not None else [])
    m = fast_measure(body, b, keys, girths)
    shapes = []
    for i in range(n):
        mi = {k: float(m[i, j]) for j, k in enumerate(keys)}
        key, kind = f"synthetic/{seed}/{i}", rng.randrange(6)
        if stated_share > 0 and pmap is not None and rng.random() < stated_share:
            shapes.append(stated_text(dict(zip(pmap.names, pheno[i])), mi, key))
        elif pmap is not None and kind >= 3:
            shapes.append(phenotype_texts(dict(zip(pmap.names, pheno[i])), mi, key, 1)[0])
        else:
            shapes.append(shape_sentence(mi) if kind == 0 else numeric_shape_text(mi, key) if kind == 1
                          else adjective_shape_text(mi, key))
    return shapes, torch.as_tensor(np.asarray(b), dtype=torch.float32), np.asarray(pheno, np.float64)


# more of the words people use than ``phenotype_texts`` has, by what the body is (never the words
# of ``eval shape-words`` that phenotype_texts lacks, nor the head's own check phrases: those measure
# how far the head carries over to words it never saw)
MORE_NOUNS = {"male": ["fellow", "dude", "son", "uncle", "boyfriend", "bloke"],
              "female": ["mom", "aunt", "daughter", "girlfriend", "madam"],
              "person": ["individual", "adult", "human", "figure"]}
MORE_AGE = {"teen": ["high-schooler", "schoolkid", "youngster"], "young": ["twenty-something", "college-age"],
            "old": ["senior citizen", "pensioner", "grey-haired", "aging"]}
MORE_BUILD = {"muscle": ["beefy", "muscle-bound", "heavily muscled", "strong", "well-built", "gym-going"],
              "muscle_nouns": ["crossfit athlete", "fitness model", "bouncer", "muscle man", "gym bro", "MMA fighter",
                               "bodybuilding champion", "personal trainer"],
              "heavy": ["portly", "rotund", "big-bellied", "husky", "large"],
              "thin": ["bony", "wiry", "slight", "gaunt", "willowy"]}


def stated_text(phenotype: dict, measures: dict, key: str) -> str:
    """One description of a body as people type it: a noun for its gender and age with a few build
    and age words (some from ``MORE_*``), sometimes its age in years ("35 years old", "aged 35"), and
    its height and/or weight in cm, m, feet and inches, kg, lb or stones, in varied sentence shapes.
    Deterministic for a ``key``."""
    import random

    from ..data.phenotype_captions import FEMALE, MALE, age_words, decade_words, phenotype_texts

    rng = random.Random(f"stated/{key}")
    g, age = float(phenotype.get("gender", 0.5)), float(phenotype.get("age", 40.0))
    muscle, weight = float(phenotype.get("muscle", 0.4)), float(phenotype.get("weight", 0.5))
    sex = "male" if g <= MALE else "female" if g >= FEMALE else "person"
    words = []
    band = "teen" if age < 20 else "young" if age <= 30 else "old" if age >= 65 else None
    if band and rng.random() < 0.5:   # the age said with any noun ("a teenage woman", "an elderly fellow")
        words.append(rng.choice(MORE_AGE[band] + age_words(age)))
    if muscle >= 0.75 and rng.random() < 0.6:
        words.append(rng.choice(MORE_BUILD["muscle"]))
    if weight >= 0.7 and muscle < 0.6 and rng.random() < 0.6:
        words.append(rng.choice(MORE_BUILD["heavy"]))
    if weight <= 0.25 and rng.random() < 0.6:
        words.append(rng.choice(MORE_BUILD["thin"]))
    k = rng.random()
    if k < 0.45:  # phenotype_texts's own words, without its numbers
        desc = phenotype_texts(phenotype, {}, key, 1)[0].rstrip(".")
        desc = desc[0].lower() + desc[1:]
    elif k < 0.85:
        nouns = MORE_NOUNS[sex] + ({"male": ["man", "guy"], "female": ["woman", "lady"]}.get(sex, ["person"]))
        if muscle >= 0.75 and rng.random() < 0.5:  # what the body does says it is strong
            nouns = MORE_BUILD["muscle_nouns"] + ([f"{'male' if sex == 'male' else 'female'} "
                                                   f"{rng.choice(MORE_BUILD['muscle_nouns'])}"] if sex != "person" else [])
        phrase = " ".join(words + [rng.choice(nouns)])
        desc = f"{'an' if phrase[0] in 'aeiou' else 'a'} {phrase}"
        if sex != "person" and rng.random() < 0.2:   # "a guy in his teens", "a lady in her seventies"
            desc += f" in {'his' if sex == 'male' else 'her'} {decade_words(age)}"
    else:
        desc = ""
    if desc and "year" not in desc and rng.random() < 0.3:   # an age in years, as the parser's forms write it
        a = int(age)
        forms = [f", {a} years old", f", aged {a}", f" aged {a}", f", {a} yo"]
        if sex != "person" and a >= 20:
            forms.append(f" in {'his' if sex == 'male' else 'her'} {a // 10 * 10}s")
        desc += rng.choice(forms)
    h, kg = measures.get("height_cm"), measures.get("mass_kg")
    H = _said_height(h, rng) if h is not None else None
    M = _said_mass(kg, rng) if kg is not None else None
    which = rng.random()
    if which < 0.15 or M is None:
        M = None if which < 0.15 or M is None else M
    if 0.15 <= which < 0.3:
        H = None
    if H is None and M is None:
        return (desc or "a person") + "."
    pron = {"male": "he", "female": "she"}.get(sex, "they")
    if H and M:
        forms = [f"{desc}, {H}, {M}", f"{desc}, {M}, {H}", f"{desc} who stands {H} and weighs {M}",
                 f"{desc} weighing {M} at {H}", f"{H} and {M}", f"{M}, {H}", f"{H} tall, {M}",
                 f"height: {H} / weight: {M}", f"weight {M}, height {H}", f"{desc}; {H} tall; {M}",
                 f"{pron} is {H} tall and weighs {M}", f"{desc} ({M}, {H} tall)"]
    elif H:
        forms = [f"{desc}, {H}", f"{desc} who is {H} tall", f"{H} tall", f"{pron} stands {H}", f"height: {H}"]
    else:
        forms = [f"{desc}, {M}", f"{desc} who weighs {M}", f"weighs {M}", f"{pron} weighs {M}", f"weight: {M}"]
    forms = [f for f in forms if desc or not f.startswith((", ", " "))]
    s = rng.choice(forms).strip(" ,;")
    if s.startswith(("(", ",")) or not s:
        s = f"{H or M}"
    return s[0].upper() + s[1:] + "."


def _said_height(cm: float, rng) -> str:
    inches = round(cm / 2.54)
    ft, i = divmod(inches, 12)
    return rng.choice([f"{cm:.0f} cm", f"{cm:.0f}cm", f"{cm / 100:.2f} m", f"{cm / 100:.2f}m", f"{ft}'{i}\"",
                       f"{ft}' {i}\"", f"{ft} ft {i}", f"{ft} ft {i} in", f"{ft} feet {i}", f"{ft} foot {i}",
                       f"{ft} feet {i} inches", f"{cm:.0f} centimetres"])


def _said_mass(kg: float, rng) -> str:
    lb = round(kg * 2.20462)
    st, rest = divmod(lb, 14)
    return rng.choice([f"{kg:.0f} kg", f"{kg:.0f}kg", f"{kg:.0f} kilos", f"{kg:.0f} kilograms", f"{lb} lb",
                       f"{lb} lbs", f"{lb} pounds", f"{st} stone {rest}", f"{st} st {rest} lb", f"{st} st {rest}"])


class Readback:
    """What ``eval shape-words`` reads back from betas, as differentiable torch functions: the
    phenotype sliders by least squares through OpenBody's shipped map (``PhenotypeMap.from_betas``
    without its clipping: the map is linear, so the read-back is a fixed (P, 10) matrix) and the
    mass of the rest mesh (its volume is an exact cubic in the betas: ``body_mass.VolumePolynomial``,
    x ``DENSITY_KG_M3``)."""

    SLIDERS = ("gender", "age", "muscle", "weight", "height")  # proportions: not read from words
    EMPHASIS = (2.0, 1.5, 1.5, 1.0, 1.0)  # man/woman, age and muscle: what the words say most plainly

    def __init__(self, body):
        import numpy as np

        from ..body.body_mass import DENSITY_KG_M3, VolumePolynomial
        from ..body.shape_from_measurements import _linear_vertices
        from ..errors import ShapeMoveError

        pmap = getattr(body, "phenotype_map", None)
        if pmap is None:
            raise ShapeMoveError(f"the head's word losses read OpenBody's phenotype sliders; {body.name} has none")
        self.names = list(pmap.names)
        self.pinv = torch.as_tensor(np.linalg.pinv(pmap.matrix.T), dtype=torch.float32)   # (P, 10)
        self.matrix = torch.as_tensor(pmap.matrix, dtype=torch.float32)                   # (P, 10)
        self.intercept = torch.as_tensor(pmap.intercept, dtype=torch.float32)
        self.ranges = pmap.ranges
        self.index = [self.names.index(n) for n in self.SLIDERS]
        emphasis = np.asarray(self.EMPHASIS) / np.mean(self.EMPHASIS)
        self.scale = torch.as_tensor(emphasis / (pmap.ranges[self.index, 1] - pmap.ranges[self.index, 0]),
                                     dtype=torch.float32)
        y0, yd, _, _, v0, vd = _linear_vertices(body)
        self.y0, self.yd = torch.as_tensor(y0, dtype=torch.float32), torch.as_tensor(yd, dtype=torch.float32)
        poly = VolumePolynomial(v0, vd.reshape(*v0.shape, -1), body.faces)
        f = DENSITY_KG_M3 / 6.0
        self.c, self.l, self.q, self.k = (torch.as_tensor(np.asarray(x) * f, dtype=torch.float32)
                                          for x in (poly.c, poly.l, poly.q, poly.k))

    def size_model(self) -> dict:
        """What a ``TextBetaHead`` with ``meets`` measures a body with (its buffers): the rest vertices'
        heights (m) as y0 + yd @ betas, this mass polynomial (kg) and the betas of one slider range
        of height and of weight."""
        names = list(self.names)
        span = torch.as_tensor(self.ranges[:, 1] - self.ranges[:, 0], dtype=torch.float32)
        dirs = torch.stack([self.matrix[names.index(k)] * span[names.index(k)] for k in ("height", "weight")])
        return {"size_y0": self.y0, "size_yd": self.yd, "mass_c": self.c.reshape(1), "mass_l": self.l,
                "mass_q": self.q, "mass_k": self.k, "meet_dirs": dirs}

    def sliders(self, betas: torch.Tensor) -> torch.Tensor:
        """(B, 10) -> (B, P) phenotype sliders, unclipped."""
        return (betas - self.intercept) @ self.pinv.T

    def to_betas(self, phenotype: torch.Tensor) -> torch.Tensor:
        """(B, P) sliders -> (B, 10): the map itself (``PhenotypeMap.to_betas``), whose read-back is exact."""
        return self.intercept + phenotype @ self.matrix

    def mass(self, betas: torch.Tensor) -> torch.Tensor:
        """(B, 10) -> (B,) kg (``fast_mass``'s number)."""
        from ..body.body_mass import cubic_in_betas

        return cubic_in_betas(betas, self.c, self.l, self.q, self.k).abs()

    def loss(self, pred: torch.Tensor, phenotype: torch.Tensor, betas: torch.Tensor, slider_weight: float,
             mass_weight: float) -> tuple:
        """(weighted loss, {"sliders": mean |slider error| / slider range (x ``EMPHASIS``), "kg": mean |mass error|}):
        the read-back sliders of ``pred`` against ``phenotype`` (B, P), the mass against ``betas``'s."""
        idx = self.index
        sl = ((self.sliders(pred)[:, idx] - phenotype[:, idx]).abs() * self.scale).mean()
        with torch.no_grad():
            true_kg = self.mass(betas)
        kg = (self.mass(pred) - true_kg).abs().mean()
        return slider_weight * sl + mass_weight * kg, {"sliders": float(sl.detach()), "kg": float(kg.detach())}


class HeadExamples:
    """What the head phase reads: the main phase's examples (``T2MExamples``: captions, the clips'
    shape texts or none, their betas) and, for a share of each batch, a body of the new-body pool
    (``synthetic_bodies``) described beside a random training caption. ``measure``: the
    differentiable height/waist of OpenBody, whose betas -> girth regression ships."""

    def __init__(self, examples, vae_body: str | None, seed: int, pool_size: int, stated_share: float = 0.0,
                 teen_share: float = 0.0, height_margin: float = 0.0):
        from ..body.load import load_body_model
        from ..body.shape_from_measurements import girth_regression, torch_measure
        from ..errors import ShapeMoveError

        body = load_body_model(None)
        if vae_body not in (None, body.name):
            raise ShapeMoveError(f"head_steps measure bodies of {body.name}; this SA-VAE was trained for "
                                 f"{vae_body!r} (set head_steps to 0)")
        self.body = body
        self.examples, self.measure = examples, torch_measure(body, MEASURES)
        self.captions = sorted({t for caps in examples.captions.values() for t in caps})
        self.pool_texts, self.pool_betas, self.pool_phenotypes = (
            synthetic_pool(body, girth_regression(body), seed, pool_size, stated_share, teen_share, height_margin)
            if pool_size
            else ([], torch.zeros(0, body.num_betas), None))

    def batch(self, rng, n: int, share: float) -> tuple[list[str], list, torch.Tensor]:
        """(motion texts, shape texts (None: no shape text), (B, 10) betas) of about ``n`` examples."""
        n_new = int(round(n * share)) if self.pool_texts else 0
        drawn = (self.examples.sample(rng) for _ in range(n - n_new))
        batch = [e for e in drawn if e.get("motion_text") is not None]  # no motion-to-text examples
        pick = [rng.randrange(len(self.pool_texts)) for _ in range(n_new)]
        motions = [e["motion_text"] for e in batch] + [rng.choice(self.captions) for _ in pick]
        shapes = [e["shape_text"] for e in batch] + [self.pool_texts[i] for i in pick]
        betas = torch.cat([torch.stack([torch.as_tensor(e["betas"]) for e in batch]) if batch else
                           torch.zeros(0, self.pool_betas.shape[1]), self.pool_betas[pick]])
        return motions, shapes, betas

    def fixed(self, rng, n_dataset: int) -> tuple:
        """Every body of the pool once (beside a random training caption) after ``n_dataset`` draws of
        the main phase's examples: (motion texts, shape texts or None, (N, 10) betas, (N,) bool: a
        pool body, (N, P) its drawn phenotype (NaN for the dataset's examples))."""
        import numpy as np

        drawn = [e for e in (self.examples.sample(rng) for _ in range(n_dataset)) if e.get("motion_text") is not None]
        n_pool = len(self.pool_texts)
        motions = [e["motion_text"] for e in drawn] + [rng.choice(self.captions) for _ in range(n_pool)]
        shapes = [e["shape_text"] for e in drawn] + list(self.pool_texts)
        betas = torch.cat([torch.stack([torch.as_tensor(e["betas"]) for e in drawn]) if drawn else
                           torch.zeros(0, self.pool_betas.shape[1]), self.pool_betas])
        P = len(getattr(self.body, "phenotype_map", None).names) if self.pool_phenotypes is not None else 0
        pheno = np.full((len(drawn) + n_pool, P), np.nan)
        if n_pool and P:
            pheno[len(drawn):] = self.pool_phenotypes
        return motions, shapes, betas, np.arange(len(motions)) >= len(drawn), pheno
