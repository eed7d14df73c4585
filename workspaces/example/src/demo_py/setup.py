from setuptools import find_packages, setup

package_name = 'demo_py'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', ['config/params.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='roc developers',
    maintainer_email='roc@example.com',
    description='Python nodes of the roc example workspace: publish and listen to readings.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'reading_publisher = demo_py.reading_publisher:main',
            'reading_listener = demo_py.reading_listener:main',
        ],
    },
)
