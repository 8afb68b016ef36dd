"""The HTML and Markdown report: renders what the study wrote (templates/)."""
