import json

import numpy as np
import pytest

from gift.core.serialization import to_jsonable


def test_containers_and_numpy_values_become_plain_json():
    value = {1: (np.float32(0.5), np.int64(3), np.bool_(True)), "a": np.arange(3), "b": [np.array([[1.0]])]}
    out = to_jsonable(value)
    assert out == {"1": [0.5, 3, True], "a": [0, 1, 2], "b": [[[1.0]]]}
    assert type(out["1"][1]) is int and type(out["1"][2]) is bool
    json.dumps(out)


@pytest.mark.parametrize("mode, nan, inf", [("keep", "nan", "inf"), ("string", "nan", "inf"), ("null-nan", None, "inf")])
def test_non_finite_floats_follow_the_mode(mode, nan, inf):
    out = to_jsonable([float("nan"), np.float64(np.inf), 1.5], nonfinite=mode)
    assert out[2] == 1.5
    if mode == "keep":
        assert np.isnan(out[0]) and out[1] == float("inf")
    else:
        assert out[0] == nan and out[1] == (inf if mode == "string" else float("inf"))


def test_unknown_mode_is_refused():
    with pytest.raises(ValueError, match="nonfinite must be one of"):
        to_jsonable([1.0], nonfinite="drop")


def test_an_intent_round_trips_through_json_and_a_bad_one_says_what_is_missing():
    from gift.core.data import Intent, Motivation, SemanticAxis
    from gift.core.errors import ValidationError

    intent = Intent("keep water-sensitive items away", [Motivation("avoid the laptop", ["mug_proximity_to_laptop"])],
                    [SemanticAxis("is it damaged by water?", ["laptop"])], source="inferred")
    assert Intent.from_dict(json.loads(json.dumps(intent.to_dict()))) == intent
    assert Intent.from_dict({"text": "pack art supplies"}) == Intent("pack art supplies")
    with pytest.raises(ValidationError, match="not an intent dict.*'text'"):
        Intent.from_dict({"motivations": []})
