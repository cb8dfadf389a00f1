"""The serial-arm family: the nR arm, gear decoupling (paper 002) and centre-of-mass motion
planning (paper 003)."""

from ...plugins import Family, Method, Template
from . import com_planning, decoupling, figures, template

FAMILY = Family(
    name="serial_arm",
    order=5,
    package=__name__,
    templates=(
        Template("serial_arm", template.SerialArmMechanism, template.build, "serial nR arm", notation=template.notation),
    ),
    methods=(
        Method("gear_decoupling", decoupling.GearDecoupling, decoupling.balance, ("serial_arm",),
               "decoupling by gears 1'-2' and mass redistribution, counter-rotating gear 3 (paper 002)",
               notation=decoupling.NOTATION, figures=figures.decoupling_figures),
        Method("com_motion_planning", com_planning.ComMotionPlanning, com_planning.balance, ("serial_arm",),
               "centre-of-mass motion planning, phi optimised (paper 003)", uses_spec=True,
               notation=com_planning.NOTATION, figures=figures.com_planning_figures),
    ),
)
