"""The paper's experiments as `gift demo` and `gift reproduce`."""
