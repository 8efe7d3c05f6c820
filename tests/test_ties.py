"""Choices among equal scores (dynid._util.ties): the same on every CPU, whose kernels move a score's last digits."""

import numpy as np

from dynid._util.ties import EQUAL, first_least


def test_the_first_of_scores_equal_but_for_their_last_digits_is_taken_whichever_is_least():
    # the UR10e's J6 as identified and folded: 6.145141338464319 and ...329 % where the digests were made; on another
    # CPU the order of the last digits may turn
    for later in (6.145141338464329, 6.145141338464309):
        errors = np.array([[6.145141338464319, 1.0], [later, 0.5]])
        assert list(first_least(errors, axis=0)) == [0, 1]
    assert first_least([3.0, 2.0, 2.0 * (1 + 0.1 * EQUAL), 1.0]) == 3
    assert first_least([2.0, 2.0 * (1 - 10 * EQUAL)]) == 1  # a difference beyond the share is one


def test_nan_is_never_the_least_and_a_tie_at_zero_takes_the_first():
    assert first_least([np.nan, 2.0, 1.0]) == 2
    assert first_least([0.0, 0.0, 1.0]) == 0
    assert list(first_least(np.array([[np.nan, 0.0], [1.0, 0.0]]), axis=0)) == [1, 0]
