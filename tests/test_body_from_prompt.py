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


def test_a_child_is_the_youngest_and_smallest_body_the_model_makes(openbody):
    """OpenBody makes no one under 13: "a child" / "a kid" is a 13-year-old, very short body
    (150 cm), not the average adult (169 cm) it was when the word was unknown; a height said wins."""
    from shapemove.core.body.measure import measure

    from shapemove.core.text.shape_words import parse_shape_words

    for prompt in ("a child hops on one foot", "a kid runs across the yard"):
        assert parse_shape_words(prompt).age == 13.0
        betas, src = body_from_prompt(openbody, prompt)
        assert src == "prompt words"
        assert measure(openbody, betas)["height_cm"] < 153
    boy, src = body_from_prompt(openbody, "a little boy jumps")   # a child, and a boy
    said = parse_shape_words("a little boy jumps")
    assert src == "prompt words" and said.age == 13.0 and said.gender == 0.0
    assert measure(openbody, boy)["height_cm"] < 153
    assert parse_shape_words("a boy runs").age == 16.0   # a boy alone: a teenager, as before
    tall, _ = body_from_prompt(openbody, "a tall kid runs")
    assert measure(openbody, tall)["height_cm"] > 180
    adult, src = body_from_prompt(openbody, "an old child walks")   # ages that disagree: no body from them
    assert src == "average adult"


def test_a_timeline_and_a_loop_take_their_body_as_one_prompt_does(openbody):
    """"a short, stocky woman walks forward, then sits down" is short and stocky throughout (the
    [BETA] head had made her 169 cm, 65 kg): the timeline's body and a loop's come from the same
    reading as a single prompt's; a shape text or given betas still win."""
    from shapemove.core.generation.loaded_generator import loaded_generator
    from shapemove.core.generation.token_sampling import body_for

    gen = loaded_generator(None)
    want, src = body_from_prompt(gen.body, "a short, stocky woman walks forward")
    predicted = np.full(gen.body.num_betas, 0.5, np.float32)   # what the [BETA] head said
    got, source = body_for(gen, "a short, stocky woman walks forward", None, None, predicted)
    assert src == source == "prompt words" and np.allclose(got, want)
    avg, source = body_for(gen, "a person walks", None, None, predicted)
    assert source == "average adult" and not avg.any()
    given, source = body_for(gen, "a short woman walks", None, np.zeros(gen.body.num_betas), predicted)
    assert source == "given"
    m = gen.generate("a short, stocky woman walks forward, then sits down", seconds=4, seed=0)
    assert m.shape_source == "prompt words" and np.allclose(m.betas, want, atol=1e-5)
