"""The gift core: data model, interfaces, alignment of features, metrics, suites, pipeline.

It imports none of drake, torch, transformers or litellm.
"""
