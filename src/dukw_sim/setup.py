from setuptools import find_packages, setup

package_name = 'dukw_sim'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='DUKW-Ling team',
    maintainer_email='dev@dukw-ling.invalid',
    description='Simulator of the DUKW-Ling on sand, in the surf and afloat.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'sim_node = dukw_sim.sim_node:main',
            'maneuver = dukw_sim.maneuver:main',
            'validate = dukw_sim.validate:main',
        ],
    },
)
