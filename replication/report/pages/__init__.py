"""The HTML pages: an experiment's, the index and scorecard, a multiverse's, a sweep's and the calibration's."""
