"""The mechanism model: joints, links, the closed loop, and family constructors."""

from screwkit.model.joints import JOINT_FREEDOMS, Joint, JointKind
from screwkit.model.linkage import Link, Linkage, LinkageError

__all__ = ["JOINT_FREEDOMS", "Joint", "JointKind", "Link", "Linkage", "LinkageError"]
