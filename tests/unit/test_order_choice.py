"""catdae.solvers.order.OrderChoice, the race of BDF orders 2 and 5 (docs/theory.md §8.6), fed
step times directly: a burst of short steps within one window neither starts a race nor
decides one, while a lasting change of rate does start one."""

from __future__ import annotations

from catdae.solvers.order import OrderChoice

OMEGA_MAX, OMEGA_1 = 4000.0, 1.0  # order 5 needs at least 4000/4 = 1000 steps per second


def _feed(race: OrderChoice, rates, t0=0.0):
    """Steps at the given rates (steps per second), one rate per step; the orders asked for."""
    t, asked = t0, []
    for r in rates:
        t += 1.0 / r
        new = race.observe(t)
        if new is not None:
            asked.append((t, new))
    return t, asked


def _settled():
    race = OrderChoice(OMEGA_MAX, OMEGA_1, t_end=1e6)
    assert race.order == 2  # ω_max/ω₁ > 100: the run starts at order 2
    t, asked = _feed(race, [100.0] * 3000)  # the first window, then one at the chosen order
    assert asked == [] and race.mode == "run" and race.skipped >= 1  # order 5 cannot win
    while race.count != 0:  # to the start of a window, so that a window's steps fill it
        t, _ = _feed(race, [100.0], t)
    return race, t


def test_a_burst_within_one_window_starts_no_race():
    race, t = _settled()
    window = race.length
    skipped = race.skipped
    # a burst of 200x shorter steps over a whole window, then the steady rate again
    t, asked = _feed(race, [20000.0] * window + [100.0] * (3 * window), t)
    assert asked == []  # order 5 was not tried
    assert race.skipped > skipped and race.order == 2 and not race.races


def test_a_lasting_change_of_rate_starts_a_race():
    race, t = _settled()
    window = race.length
    t, asked = _feed(race, [20000.0] * (3 * window), t)
    assert asked and asked[0][1] == 5  # measured twice at the new rate: order 5 is tried
