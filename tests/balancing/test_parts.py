"""The generic parts that balancing methods add to models (balpipe.balancing.parts)."""

from __future__ import annotations

import numpy as np

from balpipe import registry
from balpipe.balancing.parts import add_counter_rotation, add_counterweight
from balpipe.engine import analyse
from conftest import slider_crank_spec


def test_counter_rotation_on_the_frame_adds_only_its_spin_momentum(rng):
    spec = slider_crank_spec(rng)
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    geared = add_counter_rotation(model, "disc", carrier="frame", at=(0.3, 0.1), geared_to="crank",
                                  ratio=-2.0, inertia=0.05)
    base, an = analyse(model, t), analyse(geared, t)
    k = base.names.index("crank")
    alpha_crank = base.a[:, k, 2]
    # the massless disc spins at -2 w_crank about a fixed axis: the force is unchanged and the
    # moment changes by -d/dt(I w_disc) = 2 I alpha_crank
    assert np.max(np.abs(an.force - base.force)) <= 1e-9 * base.max_force
    assert np.allclose(an.moment - base.moment, 2 * 0.05 * alpha_crank, atol=1e-9 * base.max_moment)


def test_counterweight_moves_the_centre_of_mass_of_its_body(rng):
    model = registry.unbalanced_model(slider_crank_spec(rng))
    m0, c0, _ = model.body("crank").mass_properties()
    out = add_counterweight(model, "crank", "cw", 2.0, (-0.1, 0.0))
    m1, c1, _ = out.body("crank").mass_properties()
    assert abs(m1 - m0 - 2.0) < 1e-12
    assert abs(m1 * c1[0] - (m0 * c0[0] - 0.2)) < 1e-12
