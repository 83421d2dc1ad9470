"""The method registry: per method what it applies to, derives, evaluates, lowers."""
