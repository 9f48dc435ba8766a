"""`fingerprint`: topological mapping and localization with fingerprints of
places (Tapus, Battaglia & Siegwart 2006): features from the camera and the
laser, circular global alignment with uncertainty, a topological map of mean
fingerprints with Markov localization (agents.controllers.navigation.topomap)."""

from agents.controllers.fingerprint.controller import FingerprintController, FingerprintParams

__all__ = ["FingerprintController", "FingerprintParams"]
