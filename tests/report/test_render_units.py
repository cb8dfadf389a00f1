"""Units in the pages' free text in one display form (issue 22, point 10)."""

import markupsafe

from balpipe.report.render import environment, typeset


def test_free_text_shows_units_in_display_form_and_markup_is_untouched():
    page = environment().from_string("<p>{{ note }}</p>{{ svg|safe }}{{ n }}").render(
        note="I2 = -0.176 kg m^2, g = 9.81 m/s^2, area 2 m^2", svg=markupsafe.Markup("<script>x=m^2</script>"), n=3)
    assert page == "<p>I2 = -0.176 kg m², g = 9.81 m/s², area 2 m²</p><script>x=m^2</script>3"


def test_typeset_leaves_other_values_alone():
    assert typeset(None) is None and typeset(1.5) == 1.5 and typeset("x^2 + 1") == "x^2 + 1"
