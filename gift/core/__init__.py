"""The gift core: data model, interfaces, alignment of features, metrics, suites, pipeline, and what
demonstrations say about objects.

It imports none of drake, torch, transformers or litellm.
"""
