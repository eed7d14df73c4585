"""tf: rigid transforms and their maths (``transform``), and roc's own tf buffer (``buffer``)."""
