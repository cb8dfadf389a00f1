"""How numbers read on the pages: one formatting of every number (:mod:`.numbers`: significant
digits, no scientific notation, round-off below a stated floor shown as 0, one ratio convention)
and the display units a study's pages use (:mod:`.units`). ``results.json`` and the CSV files
never pass through here: they stay in SI units at full precision."""
