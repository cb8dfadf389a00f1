"""The serial-arm family: the nR arm, gear decoupling (paper 002) and centre-of-mass motion
planning (paper 003)."""

from ...plugins import Citation, Family, Method, Paper, Ref, Template, packaged_examples

FAMILY = Family(
    name="serial_arm",
    order=5,
    package=__name__,
    examples=packaged_examples(__file__),
    papers=(
        # paper 002 prints its authors, venue, year and DOI on its first page
        Paper("002", Citation("Shaking Force and Shaking Moment Balancing in Planar Serial Manipulators",
                              authors="V. Arakelian",
                              venue="Proceedings of the 11th World Congress on Mechanical, Chemical, and Material "
                                    "Engineering (MCM'25), Paris, France, Paper No. ICMIE 110",
                              year="2025", doi="10.11159/icmie25.110"),
              figures=("2",)),
        Paper("003", figures=("2", "3", "4")),  # stored from its abstract on: the spec's title is cited
    ),
    templates=(
        Template("serial_arm", Ref(f"{__name__}.template:SerialArmMechanism"), Ref(f"{__name__}.template:build"),
                 "serial nR arm", notation=Ref(f"{__name__}.template:notation")),
    ),
    methods=(
        Method("gear_decoupling", Ref(f"{__name__}.specs:GearDecoupling"), Ref(f"{__name__}.decoupling:balance"), ("serial_arm",),
               "decoupling by gears 1'-2' and mass redistribution, counter-rotating gear 3 (paper 002)",
               notation=Ref(f"{__name__}.decoupling:NOTATION"), figures=Ref(f"{__name__}.figures:decoupling_figures")),
        Method("com_motion_planning", Ref(f"{__name__}.specs:ComMotionPlanning"), Ref(f"{__name__}.com_planning:balance"),
               ("serial_arm",), "centre-of-mass motion planning, phi optimised (paper 003)",
               notation=Ref(f"{__name__}.com_planning:NOTATION"), figures=Ref(f"{__name__}.figures:com_planning_figures"),
               check_cost=2.0,  # paper 003's eight trajectories: phi optimised, ramps bisected
               build_cost=2.0),  # and their figures: 2.5 s (Nelder-Mead is .simplex's: no scipy)
    ),
)
