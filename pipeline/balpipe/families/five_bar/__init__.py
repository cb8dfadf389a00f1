"""The five-bar family: the fixed-sequence 5R with gear-coupled inputs and its gear balancing."""

from ...plugins import Family, Method, Paper, Ref, Template, packaged_examples

FAMILY = Family(
    name="five_bar",
    order=2,
    package=__name__,
    examples=packaged_examples(__file__),
    # stored from its abstract on: the spec's title is cited; Figs. 10a-12 drawn as the paper numbers them
    papers=(Paper("004", figures=("10a", "10b", "11", "12"), own_figures=Ref(f"{__name__}.figures:paper_figures")),),
    templates=(
        Template("five_bar", Ref(f"{__name__}.template:FiveBarMechanism"), Ref(f"{__name__}.template:build"),
                 "five-bar (5R), fixed-sequence with gear-coupled inputs", Ref(f"{__name__}.figures:figures"),
                 notation=Ref(f"{__name__}.template:NOTATION")),
    ),
    methods=(
        Method("five_bar_gear_balancing", Ref(f"{__name__}.specs:FiveBarGearBalancing"), Ref(f"{__name__}.gear_balancing:balance"),
               ("five_bar",), "counterweights + counter-rotating gears 5, 6, 7 (eqs. 9-21)",
               notation=Ref(f"{__name__}.gear_balancing:NOTATION"),
               build_cost=0.6),  # the gear stages and paper 004's figures: 1.3 s
    ),
)
