"""JSON from the crate: it writes non-finite floats as "inf", "-inf", "nan" (JSON has no
infinity); these are read back as floats."""
import json
import math

# Fields that hold names, never numbers: their values are not converted.
_TEXT_KEYS = {"plant", "campaign", "job_id", "warm_from", "plant_fingerprint", "runner", "kind", "error", "name"}
_NON_FINITE = {"inf": math.inf, "+inf": math.inf, "-inf": -math.inf, "nan": math.nan,
               "Infinity": math.inf, "-Infinity": -math.inf, "NaN": math.nan}


def numbers(value, key=None):
    """``value`` with the non-finite float strings turned into floats."""
    if isinstance(value, dict):
        return {k: numbers(v, k) for k, v in value.items()}
    if isinstance(value, list):
        return [numbers(v, key) for v in value]
    if isinstance(value, str) and key not in _TEXT_KEYS and value in _NON_FINITE:
        return _NON_FINITE[value]
    return value


def loads(text):
    """Parses the crate's JSON, non-finite floats included."""
    return numbers(json.loads(text))
