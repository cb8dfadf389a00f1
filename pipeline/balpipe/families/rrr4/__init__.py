"""The n-RRR family (paper 001): the planar parallel manipulator and its counter-masses."""

from ...plugins import Citation, Family, Method, Paper, Ref, Template, packaged_examples

FAMILY = Family(
    name="rrr4",
    order=3,
    package=__name__,
    examples=packaged_examples(__file__),
    # the title is the CORE record's (https://core.ac.uk/works/19417988, the same abstract as the stored
    # text); its authors, venue and year are not in that record's text that we could check: left empty
    papers=(Paper("001", Citation(
        "Generic method for deriving the general shaking force balance conditions of parallel manipulators with "
        "application to a redundant planar 4-RRR parallel manipulator",
        source="the CORE record core.ac.uk/works/19417988, whose abstract is the paper's"),
        figures=("2", "3", "4", "6a", "6b", "6c")),),  # Fig. 6's three panels are three designs, one spec each
    templates=(
        Template("rrr4", Ref(f"{__name__}.template:RRR4Mechanism"), Ref(f"{__name__}.template:build"),
                 "planar n-RRR parallel manipulator (4-RRR of paper 001, legs removable)",
                 notation=Ref(f"{__name__}.template:NOTATION"),
                 check_cost=0.4),  # redundant actuation: the engine's general (dense) path
    ),
    methods=(
        Method("rrr4_counter_masses", Ref(f"{__name__}.specs:RRR4Balancing"), Ref(f"{__name__}.counter_masses:balance"), ("rrr4",),
               "counter-masses: leg by leg (eqs. 8-11), from eq. 17 (Fig. 4a) and eqs. 19/21 (Fig. 6)",
               notation=Ref(f"{__name__}.counter_masses:NOTATION"), figures=Ref(f"{__name__}.figures:figures"),
               build_cost=2.0,  # 1.9-2.9 s: the topologies' designs analysed, the condition finder
               imports=("scipy.optimize",)),  # the least-mass programmes
    ),
)
