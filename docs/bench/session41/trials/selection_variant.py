"""``session40/one_case.py`` (one drawn second camera calibrated as the test does) under a variant of stripe selection
that was tried in session 41 and not kept, writing the case's report under OUT_DIR:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session41/trials/selection_variant.py \
        joint_three|five_grid_starts SEED lit|interior exposure_us|exposure OUT_DIR

``joint_three``: groups of up to three new effects are scored (``StripeProblem.joint_effects`` 3, not 2).
``five_grid_starts``: a fit started from a nested model's values also starts from five grid row times, as a first fit
does (``StripeProblem.fit_rules``' ``n_grid``, otherwise 2).
"""

import inspect
import runpy
import sys
import textwrap

from lerobot_phantom.calibration import stripes

variant = sys.argv.pop(1)
if variant == "joint_three":
    stripes.StripeProblem.joint_effects = 3
elif variant == "five_grid_starts":
    source = textwrap.dedent(inspect.getsource(stripes.StripeProblem.fit_rules))
    rule = 'n_grid = 2 if start is not None and "frames" in start.extra and not refit else 5'
    if rule not in source:
        raise SystemExit(
            "fit_rules no longer sets n_grid this way: the variant does not apply to this checkout"
        )
    namespace: dict = {}
    exec(compile(source.replace(rule, "n_grid = 5"), "fit_rules_variant", "exec"), vars(stripes), namespace)
    stripes.StripeProblem.fit_rules = namespace["fit_rules"]
else:
    raise SystemExit(f"unknown variant {variant!r}; valid: joint_three, five_grid_starts")
runpy.run_path("docs/bench/session40/one_case.py", run_name="__main__")
