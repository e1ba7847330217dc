"""A request without a shape text: the person words of the motion prompt set the body, otherwise
the average adult (core/generation/generate.body_from_prompt)."""
import numpy as np

from shapemove.core.generation.generate import body_from_prompt


def test_prompt_words_set_the_body_and_no_words_give_the_average_adult(openbody):
    pm = openbody.phenotype_map
    betas, src = body_from_prompt(openbody, "a person nods")
    assert src == "average adult" and not betas.any()
    man, src_m = body_from_prompt(openbody, "a man throws a jab")
    woman, src_w = body_from_prompt(openbody, "a woman kicks a football")
    assert src_m == src_w == "prompt words"
    assert pm.from_betas(man)[0] <= 0.25 and pm.from_betas(woman)[0] >= 0.75
    old, _ = body_from_prompt(openbody, "an elderly man sits down on a chair")
    assert pm.from_betas(old)[1] >= 65
    # numbers in a motion prompt describe the motion, never the body
    a, _ = body_from_prompt(openbody, "a muscular man walks 10 m forward for 5 seconds")
    b, _ = body_from_prompt(openbody, "a muscular man walks forward")
    np.testing.assert_allclose(a, b)
    assert pm.from_betas(a)[2] >= 0.7
