"""The contact watch's rule for a detection that was no touch, shared by the estimate, the live
listener and antenna estimate."""

from __future__ import annotations

from sensing_antenna.detection.contact_watch import ContactChange, lost_before_rest


def test_a_loss_is_judged_by_when_it_began_not_by_when_it_became_known() -> None:
    # The mean over a free period becomes known up to a period after the push began to vanish:
    # a loss dated before the head's rest at t_1 makes t_c no touch even when known after t_1
    early = ContactChange("lost", 700, t=0.9, known=1.2)
    late = ContactChange("lost", 700, t=1.05, known=1.2)
    again = ContactChange("again", 900, t=1.4, known=1.4)
    assert lost_before_rest([early, again], t_1=1.0) is early
    assert lost_before_rest([late, again], t_1=1.0) is None
    assert lost_before_rest([], t_1=1.0) is None
