"""The rule language: grammar access, parsing, the model, name resolution, term sets."""
