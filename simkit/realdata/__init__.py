"""Real receiver data: RINEX observations imported as simkit files (:mod:`.importer`), and the measured twin of a
real receiver (:mod:`.twin`, :mod:`.fidelity`). See docs/real_data.md."""
