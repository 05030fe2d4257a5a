"""Drawing: the figures, the HTML pages and the PDF of what replication.evidence decides."""
